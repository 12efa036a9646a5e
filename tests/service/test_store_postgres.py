"""
What the PostgreSQL store adds: the schema migrations (both stores), the
move from SQLite with its count and checksum, the connection bound, the
server restarting, and saves from several store instances (replicas) at
once. Against a real PostgreSQL server the tests start (``postgres_server``).
"""

from __future__ import annotations

import sqlite3
import subprocess
import threading
import time
import types
from concurrent.futures import ThreadPoolExecutor

import psycopg
import pytest
from at_once import at_once

from conftest import run_command
from service.store import SCHEMA_VERSION, FitRecord, SchemaMismatch, SQLiteStore, StoreConflict, StoreUnavailable
from service.store.move import move_sqlite_to_postgres, store_checksum
from service.store.postgres import QUICK_WAIT_S, PostgresStore, redacted

pytestmark = [pytest.mark.xdist_group("postgres"), pytest.mark.slow]


def record(fit_id: str, material_id: str = "m" * 32, name: str = "gold", kind: str = "nk", **extra) -> FitRecord:
    return FitRecord(
        id=fit_id,
        kind=kind,
        material_id=material_id,
        name=name,
        source="lab",
        material={"name": name, "coefficients": {"F0": [[0.5]] * 3}},
        metrics={"x": 1.0},
        coverage=0.95,
        **extra,
    )


def run_service(*args: str, env: dict[str, str] | None = None) -> subprocess.CompletedProcess:
    """``python -m service ARGS`` with ``env`` added (forked: tests/conftest.py's ``run_command``)."""
    import os

    return run_command("service", *args, timeout=120, env={**os.environ, **(env or {})})


class TestMigrations:
    def test_newer_schema_refused_on_both(self, tmp_path, postgres_url):
        lite = SQLiteStore(tmp_path / "s.sqlite3")
        with sqlite3.connect(lite.path) as connection:
            connection.execute("INSERT INTO schema_migrations VALUES (?, 'from the future', 0)", (SCHEMA_VERSION + 1,))
        lite.close()
        with pytest.raises(SchemaMismatch, match=f"version {SCHEMA_VERSION + 1}, newer than this code"):
            SQLiteStore(tmp_path / "s.sqlite3")
        store = PostgresStore(postgres_url)
        store.transaction(
            lambda c: c.execute(
                "INSERT INTO schema_migrations VALUES (%s, 'from the future', 0)", (SCHEMA_VERSION + 1,)
            )
        )
        store.close()
        with pytest.raises(SchemaMismatch, match="newer than this code"):
            PostgresStore(postgres_url)
        # The service refuses to start, in one line.
        result = run_service("--port", "0", env={"COATED_STORE_URL": postgres_url})
        assert result.returncode == 1
        (line,) = result.stderr.strip().splitlines()
        assert line.startswith("python -m service: cannot start: the store's schema is version")
        assert "password" not in result.stderr and postgres_url.split(":")[2].split("@")[0] not in result.stderr

    def test_older_schema_by_command(self, tmp_path, postgres_url):
        data = tmp_path / "data"
        data.mkdir()
        path = data / "store.sqlite3"
        old = sqlite3.connect(path)  # a store of the schema before versions (version 0)
        old.executescript(
            "CREATE TABLE fits (id TEXT PRIMARY KEY, kind TEXT NOT NULL, material_id TEXT NOT NULL,"
            " created_at REAL NOT NULL, record TEXT NOT NULL);"
        )
        r = record("1" * 32)
        old.execute("INSERT INTO fits VALUES (?, ?, ?, ?, ?)", (r.id, r.kind, r.material_id, 1.0, r.to_json()))
        old.commit()
        old.close()
        with pytest.raises(SchemaMismatch, match="run `python -m service migrate`"):
            SQLiteStore(path, migrate=False)
        result = run_service("migrate", "--data-dir", str(data))
        assert result.returncode == 0, result.stderr
        assert f"schema version 0 -> {SCHEMA_VERSION}" in result.stdout
        again = run_service("migrate", "--data-dir", str(data))
        assert f"schema version {SCHEMA_VERSION} -> {SCHEMA_VERSION}" in again.stdout
        store = SQLiteStore(data / "store.sqlite3", migrate=False)
        assert store.material_version(r.material_id) == 1 and store.latest_fit(r.material_id) == r
        store.close()

    def test_bad_store_settings_refused_at_start(self):
        for env, message in (
            ({"COATED_STORE_URL": "mysql://x/y"}, "must be a postgresql:// URL"),
            ({"COATED_STORE_POOL_MIN": "5", "COATED_STORE_POOL_MAX": "2"}, "must not exceed"),
        ):
            result = run_service("--port", "0", env=env)
            assert result.returncode == 2 and message in result.stderr and "Traceback" not in result.stderr

    def test_unreachable_server_refused_at_start(self):
        from conftest import free_port

        url = f"postgresql://coated:secret-pw@127.0.0.1:{free_port()}/none"
        result = run_service("--port", "0", env={"COATED_STORE_URL": url})
        assert result.returncode == 1
        (line,) = result.stderr.strip().splitlines()
        assert line.startswith("python -m service: cannot start: the store at postgresql://coated@127.0.0.1")
        assert "cannot be reached" in line and "secret-pw" not in result.stderr

    def test_replicas_migrate_at_once(self, postgres_url):
        with ThreadPoolExecutor(4) as pool:
            stores = list(pool.map(lambda _: PostgresStore(postgres_url), range(4)))
        assert sorted(s.migrated for s in stores) == [(0, SCHEMA_VERSION)] + [(SCHEMA_VERSION,) * 2] * 3
        for store in stores:
            store.close()


class TestMove:
    def test_sqlite_to_postgres_count_and_checksum(self, tmp_path, postgres_server):
        lite = SQLiteStore(tmp_path / "data" / "store.sqlite3")
        for i in range(30):
            lite.put_fit(record(f"{i:032x}", material_id=f"{i % 7:032x}", name=f"m{i % 7}"))
        lite.put_fit(record(f"{3:032x}"), save=False)
        lite.put_fit(
            record(f"{101:032x}", kind="curves", nk_id="e" * 32),
            save=False,
            nk={"wavelength_nm": [400.0, 600.0], "n": [0.2, 0.3], "k": [3.0, 2.0]},
        )
        lite.put_fit(record(f"{100:032x}", material_id="Au", kind="library"))
        in_bin = lite.delete_material(f"{6:032x}").deleted_at  # the bin moves too
        lite.close()
        url = postgres_server.database()
        result = run_service(
            "migrate", "--from-sqlite", str(tmp_path / "data" / "store.sqlite3"), env={"COATED_STORE_URL": url}
        )
        assert result.returncode == 0, result.stderr
        with sqlite3.connect(tmp_path / "data" / "store.sqlite3") as connection:
            checksum, counts = store_checksum(connection)
        assert counts == {"fits": 32, "saves": 31, "materials": 8, "nk_records": 1}
        assert f"moved 32 fits, 31 saves, 8 materials from {tmp_path}" in result.stdout
        assert f"checksum {checksum} (source and target agree)" in result.stdout
        assert url not in result.stdout and redacted(url) in result.stdout
        target = PostgresStore(url)
        assert [m.name for m in target.saved_materials()] == [f"m{i}" for i in range(6)]
        assert target.material(f"{6:032x}").deleted_at == in_bin
        assert target.material_version(f"{1:032x}") == 5
        assert target.get_nk("e" * 32)["n"] == [0.2, 0.3]  # the drafts' n, k records move too
        target.put_fit(record("f" * 32, material_id="new" * 10))  # seq continues after the moved log
        assert target.saved_materials()[-1].material_id == "new" * 10
        # A second move into the now non-empty store is refused and changes nothing.
        with pytest.raises(StoreUnavailable, match="already holds 33 fits"):
            move_sqlite_to_postgres(tmp_path / "data" / "store.sqlite3", target)
        target.close()

    def test_move_needs_a_target(self, tmp_path):
        result = run_service("migrate", "--from-sqlite", str(tmp_path / "x.sqlite3"))
        assert result.returncode == 2 and "needs COATED_STORE_URL" in result.stderr


class TestConnections:
    @pytest.mark.parametrize("connect_s", [0.0, 0.6], ids=["quick-connections", "slow-connections"])
    def test_pool_bound_holds_under_load(self, postgres_server, postgres_url, monkeypatch, connect_s):
        """
        24 threads on 3 connections: the server never sees more than 3, and
        the store opens no plain connection beside the pool (its check for a
        server that went away) while the pool is merely busy; the start-up's
        own first connection becomes the pool's. Slow connections (0.6 s
        each, past QUICK_WAIT_S, as a loaded machine made them on CI): the
        calls wait for the pool's growth instead of asking the server.
        """
        store = PostgresStore(postgres_url, pool_min=1, pool_max=3, pool_timeout_s=30)
        probes = TestFaults.counted_probes(monkeypatch)
        plain_connect = psycopg.Connection.connect.__func__

        def slow_connect(cls, *args, **kwargs):
            time.sleep(connect_s)
            return plain_connect(cls, *args, **kwargs)

        monkeypatch.setattr(psycopg.Connection, "connect", classmethod(slow_connect))
        dbname = postgres_url.rsplit("/", 1)[1]
        peak, stop = [0], threading.Event()

        def watch():
            while not stop.is_set():
                peak[0] = max(peak[0], postgres_server.connections(dbname))

        watcher = threading.Thread(target=watch)
        watcher.start()

        def call(i: int) -> None:
            if i < 0:  # three slow calls first: the queue's waits pass QUICK_WAIT_S on an idle machine too
                store.transaction(lambda c: c.execute("SELECT pg_sleep(1)"))
            else:
                store.put_fit(record(f"{i:032x}", material_id=f"{i:032x}"))

        with ThreadPoolExecutor(24) as pool:
            list(pool.map(call, range(-3, 300)))
        stop.set()
        watcher.join()
        assert 1 <= peak[0] <= 3
        assert probes["attempts"] == 0, probes
        assert len(store.saved_materials()) == 300
        assert store.describe()["connections_max"] == 3
        store.close()

    def test_pool_timeout_is_503_with_retry_after(self, postgres_url):
        store = PostgresStore(postgres_url, pool_min=1, pool_max=1, pool_timeout_s=0.3)
        held = threading.Event()
        release = threading.Event()

        def hold(connection):
            held.set()
            release.wait(10)

        worker = threading.Thread(target=store.transaction, args=(hold,))
        worker.start()
        held.wait(10)
        with pytest.raises(StoreUnavailable, match="COATED_STORE_POOL_TIMEOUT_S") as refused:
            store.get_fit("1" * 32)
        assert refused.value.status == 503 and refused.value.retry_after <= 5
        release.set()
        worker.join()
        store.close()

    def test_role_connection_limit_enforced_by_the_server(self, postgres_server):
        from postgres_server import ROLE_CONNECTION_LIMIT

        url = postgres_server.database()
        postgres_server.wait_for_no_connections()  # the limit counts the role's connections to every database
        with postgres_server.admin() as admin:
            admin.execute("ALTER ROLE coated CONNECTION LIMIT 2")
        try:
            first = PostgresStore(url, pool_min=2, pool_max=2)
            with pytest.raises(StoreUnavailable, match="CONNECTION LIMIT|too many connections"):
                PostgresStore(url, pool_min=1, pool_max=1, pool_timeout_s=1)
            first.close()
        finally:
            with postgres_server.admin() as admin:
                admin.execute(f"ALTER ROLE coated CONNECTION LIMIT {ROLE_CONNECTION_LIMIT}")


class TestFaults:
    def test_server_restart_503_then_recovers(self, postgres_server, postgres_url):
        store = PostgresStore(postgres_url, pool_timeout_s=1)
        store.put_fit(record("1" * 32))
        postgres_server.stop()
        with pytest.raises(StoreUnavailable) as down:
            store.put_fit(record("2" * 32, material_id="b" * 32))
        assert down.value.retry_after <= 5
        with pytest.raises(StoreUnavailable, match="unavailable"):
            store.writable()
        postgres_server.start()
        deadline = time.monotonic() + 10
        while True:  # no reopening: the pool reconnects by itself within a few seconds
            try:
                store.put_fit(record("2" * 32, material_id="b" * 32))
                break
            except StoreUnavailable:
                assert time.monotonic() < deadline, "the store did not recover within 10 s"
                time.sleep(0.2)
        assert [m.material_id for m in store.saved_materials()] == ["m" * 32, "b" * 32]
        store.close()

    def test_the_first_call_after_the_server_went_away_is_refused_at_once(self, postgres_server, postgres_url):
        """
        Not a wait of the pool timeout (5 s here) for a connection the pool
        cannot make: past QUICK_WAIT_S the call asks the server itself, whose
        refusal answers it. Bound: half the pool timeout (the probe is a
        refused connection on loopback, milliseconds; without it the call
        took the whole 5 s).
        """
        store = PostgresStore(postgres_url, pool_timeout_s=5)
        store.put_fit(record("1" * 32))
        postgres_server.stop()
        try:
            start = time.monotonic()
            with pytest.raises(StoreUnavailable, match="unavailable") as down:
                store.get_fit("1" * 32)
            assert time.monotonic() - start < 2.5
            assert "COATED_STORE_POOL_TIMEOUT_S" not in str(down.value)  # the server's refusal, not a timeout
        finally:
            postgres_server.start()
        store.close()

    @staticmethod
    def counted_probes(monkeypatch) -> dict:
        """
        The store's plain connections (its probes, ``psycopg.connect`` in
        service.store.postgres; the pool connects otherwise), each held 0.2 s
        so that a burst overlaps it: how many, and the most at once.
        """
        import service.store.postgres as postgres

        seen = {"attempts": 0, "now": 0, "most": 0}
        lock = threading.Lock()

        def connect(*args, **kwargs):
            with lock:
                seen["attempts"] += 1
                seen["now"] += 1
                seen["most"] = max(seen["most"], seen["now"])
            try:
                time.sleep(0.2)
                return psycopg.connect(*args, **kwargs)
            finally:
                with lock:
                    seen["now"] -= 1

        monkeypatch.setattr(postgres, "psycopg", types.SimpleNamespace(**{**vars(psycopg), "connect": connect}))
        return seen

    def test_a_burst_after_a_fault_shares_one_connection_check(self, postgres_url, monkeypatch):
        """
        Calls that come while the store checks whether the server is back
        (after a connection fault, as ``_down`` marks it) share that check:
        one plain connection beside the pool at a time (at most pool_max + 1
        in all, docs/deploy.md), not one each.
        """
        store = PostgresStore(postgres_url, pool_max=4, pool_timeout_s=5)
        store.put_fit(record("1" * 32))
        seen = self.counted_probes(monkeypatch)
        store._down = True  # as a connection fault leaves it
        answers = at_once(lambda: store.get_fit("1" * 32), n=16)
        assert all(isinstance(a, FitRecord) and a.id == "1" * 32 for a in answers), answers
        assert seen["most"] == 1 and seen["attempts"] < 16, seen
        store.close()

    def test_a_burst_while_the_server_is_down_shares_each_refusal(self, postgres_server, postgres_url, monkeypatch):
        """
        Every call is refused at once (503) by the server's own refusal (the
        pool's reconnection's, or a plain connection's), with at most one
        plain connection attempt at a time.
        """
        store = PostgresStore(postgres_url, pool_max=4, pool_timeout_s=5)
        store.put_fit(record("1" * 32))
        postgres_server.stop()
        try:
            seen = self.counted_probes(monkeypatch)
            start = time.monotonic()
            answers = at_once(lambda: store.get_fit("1" * 32), n=16)
            elapsed = time.monotonic() - start
        finally:
            postgres_server.start()
        assert all(isinstance(a, StoreUnavailable) and "unavailable" in str(a) for a in answers), answers
        assert not any("COATED_STORE_POOL_TIMEOUT_S" in str(a) for a in answers), answers
        assert seen["most"] <= 1, seen
        # Bound: the first call's quick wait and 16 refusals of 0.2 s one after another, at worst, under the
        # 16 pool timeouts (80 s) that waiting calls would take.
        assert elapsed < QUICK_WAIT_S + 16 * 0.2 + 5, elapsed
        store.close()

    def test_a_busy_pool_still_waits_for_its_connection(self, postgres_url):
        """A call that waits past QUICK_WAIT_S on a busy pool (the server up) gets the freed connection, no 503."""
        store = PostgresStore(postgres_url, pool_min=1, pool_max=1, pool_timeout_s=5)
        store.put_fit(record("1" * 32))
        held = threading.Event()

        def hold(connection):
            held.set()
            time.sleep(4 * QUICK_WAIT_S)

        worker = threading.Thread(target=store.transaction, args=(hold,))
        worker.start()
        held.wait(10)
        start = time.monotonic()
        assert store.get_fit("1" * 32).id == "1" * 32
        assert time.monotonic() - start >= 2 * QUICK_WAIT_S  # it did wait for the held connection
        worker.join()
        store.close()

    def test_two_instances_one_winner(self, postgres_url):
        replicas = [PostgresStore(postgres_url, pool_max=4) for _ in range(2)]
        m = "c" * 32
        barrier = threading.Barrier(20)

        def save(i: int):
            barrier.wait()
            try:
                replicas[i % 2].put_fit(record(f"{i:032x}", material_id=m, kind="curves"), expected_version=0)
                return "won"
            except StoreConflict:
                return "409"

        with ThreadPoolExecutor(20) as pool:
            answers = list(pool.map(save, range(20)))
        assert answers.count("won") == 1 and answers.count("409") == 19
        assert replicas[0].material_version(m) == replicas[1].material_version(m) == 1
        for store in replicas:
            store.close()


def test_a_server_whose_port_was_taken_starts_on_another(monkeypatch):
    """The tests' PostgreSQL server (tests/postgres_server.py): a port taken between its choice and the bind
    ("Address already in use", another test's server) makes the first start try another port."""
    import postgres_server
    from ports import taken_first

    with taken_first(monkeypatch, postgres_server, "_free_port") as (port, first):
        server = postgres_server.PostgresServer()
        try:
            assert not first and server.port != port
            with server.admin() as connection:
                assert connection.execute("SELECT 1").fetchone() == (1,)
        finally:
            server.close()
