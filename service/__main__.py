"""
``python -m service [--host 127.0.0.1] [--port 8000] [--data-dir DIR]``:
start the HTTP service with uvicorn. Other settings come from ``COATED_*``
environment variables (:class:`service.config.Settings`).
"""

from __future__ import annotations

import argparse
import sys

import uvicorn
from pydantic import ValidationError

from .config import Settings
from .main import create_app


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
    uvicorn.run(create_app(settings), host=args.host, port=args.port, log_level="info")
    return 0


if __name__ == "__main__":
    sys.exit(main())
