"""
``python -m service [--host 127.0.0.1] [--port 8000] [--data-dir DIR]``:
start the HTTP service (:func:`service.runtime.server.serve`). Other settings come
from ``COATED_*`` environment variables (:class:`service.config.Settings`);
``COATED_STORE_URL=postgresql://...`` puts the store on PostgreSQL. A store
that cannot be opened, is damaged, cannot be written or has a schema newer
than this code, or a temporary directory (``TMPDIR``) whose path is too
long for the fork server's Unix socket, stops the start with one line on
stderr (exit status 1).

``python -m service migrate [--data-dir DIR] [--from-sqlite FILE]``: bring
the configured store's schema to this code's version (what a start does
unless ``COATED_STORE_MIGRATE=false``); with ``--from-sqlite``, copy that
SQLite store into the (empty) PostgreSQL store of ``COATED_STORE_URL`` and
print the count and checksum of what moved.

The application, the server and the fork server (FastAPI, the fitting core,
scipy, colour-science: about a second of CPU time) are imported only once
the arguments and settings are valid, so a start refused for them, and the
``migrate`` command, answer without that cost.
"""

from __future__ import annotations

import argparse
import sys

from pydantic import ValidationError

from .config import Settings
from .store import StoreError, open_store

PROG = "python -m service"


def check_store(settings: Settings) -> str | None:
    """None when the store opens, is sound and can be written; else why not, in one line."""
    try:
        store = open_store(settings)
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


def _settings(overrides: dict) -> Settings | None:
    try:
        return Settings(**overrides)
    except ValidationError as error:
        messages = "; ".join(e["msg"].removeprefix("Value error, ") for e in error.errors())
        print(f"{PROG}: {messages}", file=sys.stderr)
        return None


def migrate_command(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(prog=f"{PROG} migrate", description=__doc__.split("\n\n")[1])
    parser.add_argument("--data-dir", default=None, help="SQLite store directory (without COATED_STORE_URL)")
    parser.add_argument(
        "--from-sqlite",
        default=None,
        metavar="FILE",
        help="copy this SQLite store (store.sqlite3) into the PostgreSQL store",
    )
    args = parser.parse_args(argv)
    settings = _settings({} if args.data_dir is None else {"data_dir": args.data_dir})
    if settings is None:
        return 2
    if args.from_sqlite is not None and settings.store_url is None:
        print(f"{PROG} migrate: --from-sqlite needs COATED_STORE_URL=postgresql://... (the target)", file=sys.stderr)
        return 2
    try:
        store = open_store(settings, migrate=True)
    except StoreError as error:
        print(f"{PROG} migrate: {error}", file=sys.stderr)
        return 1
    try:
        before, after = store.migrated
        where = store.describe().get("url") or store.describe().get("path")
        print(f"store {where}: schema version {before} -> {after}")
        if args.from_sqlite is not None:
            from .store.move import move_sqlite_to_postgres

            report = move_sqlite_to_postgres(args.from_sqlite, store)
            print(report.line(args.from_sqlite, where))
    except StoreError as error:
        print(f"{PROG} migrate: {error}", file=sys.stderr)
        return 1
    finally:
        store.close()
    return 0


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if argv[:1] == ["migrate"]:
        return migrate_command(argv[1:])
    parser = argparse.ArgumentParser(
        prog=PROG,
        description=__doc__.split("\n")[1],
        epilog=f"{PROG} migrate --help: the schema and the move to PostgreSQL",
    )
    parser.add_argument("--host", default="127.0.0.1", help="bind address (default 127.0.0.1)")
    parser.add_argument("--port", type=int, default=8000, help="TCP port (default 8000)")
    parser.add_argument("--data-dir", default=None, help="store directory (default ./data or COATED_DATA_DIR)")
    args = parser.parse_args(argv)
    if not 0 <= args.port <= 65535:
        parser.error(f"--port must lie in [0, 65535], got {args.port}")
    overrides = {"host": args.host}
    if args.data_dir is not None:
        overrides["data_dir"] = args.data_dir
    settings = _settings(overrides)
    if settings is None:
        return 2
    from fitting.cli.plugins import load_plugins

    from .runtime import start_fork_server
    from .main import create_app
    from .runtime import serve

    # Before the fork server: its forks, the workers, have the plugins' formats and kinds too.
    try:
        load_plugins(settings.plugins)
    except ValueError as error:
        print(f"{PROG}: cannot start: {error}", file=sys.stderr)
        return 1
    # Before the store is opened and before any thread: the workers' fork server, forked from here.
    try:
        start_fork_server()
    except ValueError as error:
        print(f"{PROG}: cannot start: {error}", file=sys.stderr)
        return 1
    problem = check_store(settings)
    if problem is not None:
        print(f"{PROG}: cannot start: {problem}", file=sys.stderr)
        return 1
    serve(create_app(settings), settings, args.host, args.port)
    return 0


if __name__ == "__main__":
    sys.exit(main())
