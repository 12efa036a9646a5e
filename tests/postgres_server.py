"""
A throwaway PostgreSQL server for the tests and the benchmark.

:class:`PostgresServer` runs ``initdb`` and ``pg_ctl`` from the installed
binaries (``/usr/lib/postgresql/<version>/bin``, Debian's ``postgresql``
package, which ``scripts/bootstrap`` installs) in a fresh temporary
directory, listening on a free loopback port only (no Unix socket outside
its directory). PostgreSQL refuses to run as root; when the tests run as
root the server runs as the ``postgres`` system user that the Debian
package creates (``setpriv``, no login shell or sudo needed), and its
directory is handed to that user. Missing binaries are an install bug and
fail loudly, never a skip.

It makes a role ``coated`` (password, ``CONNECTION LIMIT`` as the docs
advise) and one database per :meth:`database` call, so tests sharing the
server never share a store.
"""

from __future__ import annotations

import contextlib
import glob
import os
import pwd
import secrets
import shutil
import socket
import subprocess
import tempfile
import time
from pathlib import Path

import psycopg

__all__ = ["PostgresServer", "postgres_bin_dir"]

ROLE = "coated"
ROLE_CONNECTION_LIMIT = 40
MAX_CONNECTIONS = 60


def postgres_bin_dir() -> Path:
    """The newest ``/usr/lib/postgresql/*/bin`` with ``initdb``; RuntimeError naming the fix if none."""
    found = sorted(glob.glob("/usr/lib/postgresql/*/bin/initdb"), key=lambda p: int(Path(p).parts[-3]))
    if not found:
        raise RuntimeError(
            "PostgreSQL is not installed (no /usr/lib/postgresql/*/bin/initdb): "
            "run scripts/bootstrap, which installs the Debian package `postgresql`"
        )
    return Path(found[-1]).parent


def _free_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


class PostgresServer:
    """One PostgreSQL server in a temporary directory on ``127.0.0.1:<port>``; see the module docstring."""

    def __init__(self, user: str = "postgres") -> None:
        self.bin = postgres_bin_dir()
        self.root = Path(tempfile.mkdtemp(prefix="coated-pg-"))
        self.data = self.root / "data"
        self.log = self.root / "server.log"
        self.port = _free_port()
        self.password = secrets.token_hex(12)
        self._admin_password = secrets.token_hex(12)
        self._as: list[str] = []
        if os.getuid() == 0:  # postgres refuses root: run it as the Debian package's system user
            try:
                account = pwd.getpwnam(user)
            except KeyError:
                raise RuntimeError(
                    f"no system user {user!r} to run PostgreSQL as (it refuses root): "
                    "run scripts/bootstrap, whose Debian package `postgresql` makes it"
                ) from None
            os.chown(self.root, account.pw_uid, account.pw_gid)
            self._as = ["setpriv", f"--reuid={account.pw_uid}", f"--regid={account.pw_gid}", "--clear-groups"]
        self.root.chmod(0o700)
        pwfile = self.root / "admin.pw"
        pwfile.write_text(self._admin_password + "\n")
        if self._as:
            os.chown(pwfile, account.pw_uid, account.pw_gid)
        self._run(
            self.bin / "initdb",
            "-D",
            self.data,
            "-U",
            "admin",
            "--auth-local=trust",
            "--auth-host=scram-sha-256",
            f"--pwfile={pwfile}",
            "-E",
            "UTF8",
            "--no-instructions",
        )
        pwfile.unlink()
        self._first_start()
        with self.admin() as connection:
            connection.execute(
                f"CREATE ROLE {ROLE} LOGIN PASSWORD '{self.password}' CONNECTION LIMIT {ROLE_CONNECTION_LIMIT}"
            )
        self._databases = 0

    def _run(self, *command, check: bool = True) -> subprocess.CompletedProcess:
        result = subprocess.run(
            [*self._as, *map(str, command)], capture_output=True, text=True, timeout=120, cwd=self.root
        )
        if check and result.returncode != 0:
            raise RuntimeError(
                f"{' '.join(map(str, command))} failed ({result.returncode}):\n"
                f"{result.stdout}\n{result.stderr}\n{self.log_text()}"
            )
        return result

    def log_text(self) -> str:
        with contextlib.suppress(OSError):
            return self.log.read_text(errors="replace")[-4000:]
        return ""

    def _first_start(self, tries: int = 3) -> None:
        """
        The first start, on another free port while the one chosen was taken
        between :func:`_free_port` and the server's bind (another test's
        server: "Address already in use"), ``tries`` times in all.
        """
        for attempt in range(tries):
            try:
                self.start()
                return
            except RuntimeError as error:
                if attempt + 1 == tries or "already in use" not in str(error):
                    raise
                self.port = _free_port()

    def start(self) -> None:
        """Start on the same port (and data) as before."""
        options = (
            f"-c listen_addresses=127.0.0.1 -p {self.port} -c unix_socket_directories={self.root} "
            f"-c max_connections={MAX_CONNECTIONS} -c superuser_reserved_connections=3"
        )
        self._run(self.bin / "pg_ctl", "-D", self.data, "-l", self.log, "-o", options, "-w", "-t", "60", "start")

    def stop(self, mode: str = "fast") -> None:
        """Stop (``fast``: roll back open transactions and disconnect clients; ``immediate``: a crash)."""
        self._run(self.bin / "pg_ctl", "-D", self.data, "-m", mode, "-w", "-t", "60", "stop", check=False)

    def restart(self, down_s: float = 0.0) -> None:
        self.stop()
        time.sleep(down_s)
        self.start()

    def admin(self) -> psycopg.Connection:
        return psycopg.connect(
            host="127.0.0.1",
            port=self.port,
            user="admin",
            dbname="postgres",
            password=self._admin_password,
            autocommit=True,
            connect_timeout=10,
        )

    def url_of(self, dbname: str) -> str:
        return f"postgresql://{ROLE}:{self.password}@127.0.0.1:{self.port}/{dbname}"

    def database(self, prefix: str = "store") -> str:
        """A new empty database owned by the role ``coated``; its URL."""
        self._databases += 1
        name = f"{prefix}_{os.getpid()}_{self._databases}_{secrets.token_hex(3)}"
        with self.admin() as connection:
            connection.execute(f"CREATE DATABASE {name} OWNER {ROLE}")
        return self.url_of(name)

    def connections(self, dbname: str | None = None) -> int:
        """Connections of the role ``coated`` now (to ``dbname``, if given)."""
        with self.admin() as connection:
            query = "SELECT COUNT(*) FROM pg_stat_activity WHERE usename = %s"
            args = [ROLE]
            if dbname:
                query += " AND datname = %s"
                args.append(dbname)
            return connection.execute(query, args).fetchone()[0]

    def wait_for_no_connections(self, timeout_s: float = 10.0) -> None:
        """
        Until the role ``coated`` has no connection: the server counts a
        closed connection against the role's CONNECTION LIMIT until its
        backend has exited, which an earlier test's closed store may not
        have yet on a loaded machine.
        """
        deadline = time.monotonic() + timeout_s
        while self.connections():
            if time.monotonic() > deadline:
                with self.admin() as connection:
                    rows = connection.execute(
                        "SELECT datname, application_name, state FROM pg_stat_activity WHERE usename = %s", [ROLE]
                    ).fetchall()
                raise AssertionError(f"the role {ROLE} still has connections after {timeout_s:g} s: {rows}")
            time.sleep(0.05)

    def close(self) -> None:
        self.stop("immediate")
        shutil.rmtree(self.root, ignore_errors=True)
