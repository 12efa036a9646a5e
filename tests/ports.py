"""
``taken_first(monkeypatch, module, name)``: the free-port function ``module.name`` patched so that
its first answer is a port held open by a listening socket (a port taken between the choice and
the bind), then the real function's; yields that port and a list that is empty once it was given.
"""

from __future__ import annotations

import contextlib
import socket
from typing import Iterator


@contextlib.contextmanager
def taken_first(monkeypatch, module, name: str) -> Iterator[tuple[int, list[int]]]:
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        first = [port]
        real = getattr(module, name)
        monkeypatch.setattr(module, name, lambda: first.pop() if first else real())
        yield port, first
