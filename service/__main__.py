"""
``python -m service [--host 127.0.0.1] [--port 8000] [--data-dir DIR]``:
start the HTTP service (:func:`service.server.serve`). Other settings come
from ``COATED_*`` environment variables (:class:`service.config.Settings`).
A store that cannot be opened, is damaged or cannot be written stops the
start with one line on stderr (exit status 1).
"""

from __future__ import annotations

import argparse
import sys

from pydantic import ValidationError

from .config import Settings
from .main import create_app
from .server import serve
from .store import SQLiteStore, StoreError


def check_store(settings: Settings) -> str | None:
    """None when the store opens, is sound and can be written; else why not, in one line."""
    try:
        store = SQLiteStore(settings.store_path, settings.store_max_bytes, settings.store_min_free_bytes)
    except StoreError as error:
        return str(error)
    try:
        store.check()
        problem = store.writable()
        return None if problem is None or "free" in problem or "quota" in problem else problem
    except StoreError as error:
        return str(error)
    finally:
        store.close()


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m service", description=__doc__.split("\n")[1])
    parser.add_argument("--host", default="127.0.0.1", help="bind address (default 127.0.0.1)")
    parser.add_argument("--port", type=int, default=8000, help="TCP port (default 8000)")
    parser.add_argument("--data-dir", default=None, help="store directory (default ./data or COATED_DATA_DIR)")
    args = parser.parse_args(argv)
    if not 0 <= args.port <= 65535:
        parser.error(f"--port must lie in [0, 65535], got {args.port}")
    overrides = {"host": args.host}
    if args.data_dir is not None:
        overrides["data_dir"] = args.data_dir
    try:
        settings = Settings(**overrides)
    except ValidationError as error:
        messages = "; ".join(e["msg"].removeprefix("Value error, ") for e in error.errors())
        print(f"python -m service: {messages}", file=sys.stderr)
        return 2
    problem = check_store(settings)
    if problem is not None:
        print(f"python -m service: cannot start: {problem}", file=sys.stderr)
        return 1
    serve(create_app(settings), settings, args.host, args.port)
    return 0


if __name__ == "__main__":
    sys.exit(main())
