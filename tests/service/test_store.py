"""
The store contract, run against both stores (SQLite and PostgreSQL on a
real server the tests start): content-addressed, write-once records that
survive reopening, the save log, versions; then what only SQLite has.
"""

from __future__ import annotations

import sqlite3

import pytest

from service.store import SCHEMA_VERSION, FitRecord, SQLiteStore, Store, StoreConflict

POSTGRES = pytest.param("postgresql", marks=[pytest.mark.xdist_group("postgres"), pytest.mark.slow])


def record(fit_id: str, material_id: str = "m" * 32, kind: str = "nk", name: str = "gold", **extra) -> FitRecord:
    return FitRecord(
        id=fit_id, kind=kind, material_id=material_id, name=name, source="lab",
        material={"name": name, "coefficients": {"F0": [[0.5]] * 3}}, metrics={"x": 1.0}, **extra,
    )


def open_store(kind: str, tmp_path, request):
    if kind == "sqlite":
        return SQLiteStore(tmp_path / "store.sqlite3")
    from service.store.postgres import PostgresStore

    return PostgresStore(request.getfixturevalue("postgres_url"))


@pytest.fixture(params=["sqlite", POSTGRES])
def store(request, tmp_path):
    opened = open_store(request.param, tmp_path, request)
    yield opened
    opened.close()


class TestStoreContract:
    def test_is_a_store(self, store):
        assert isinstance(store, Store)
        described = store.describe()
        assert described["kind"] == store.kind and described["schema_version"] == SCHEMA_VERSION
        assert store.migrated == (0, SCHEMA_VERSION)

    def test_round_trip(self, store):
        saved = store.put_fit(record("1" * 32, nk={"wavelength_nm": [1.0, 2.0], "n": [1, 1], "k": [0, 0]}))
        assert saved.created_at > 0
        assert store.get_fit("1" * 32) == saved
        assert store.get_fit("2" * 32) is None

    def test_write_once(self, store):
        first = store.put_fit(record("1" * 32, name="first"))
        again = store.put_fit(record("1" * 32, name="second"))
        assert again == first and again.name == "first"
        assert store.latest_fit(first.material_id) == first

    def test_saving_an_earlier_fit_again_makes_it_latest(self, store):
        # An artist's undo then save: the earlier state is the material's latest.
        a = store.put_fit(record("1" * 32, material_id="m" * 32, kind="curves", name="A"))
        b = store.put_fit(record("2" * 32, material_id="m" * 32, kind="curves", name="B"))
        assert store.latest_fit("m" * 32) == b
        store.put_fit(a)
        assert store.latest_fit("m" * 32) == a
        (row,) = store.saved_materials()
        assert row.latest_fit_id == a.id and row.name == "A"

    def test_latest_and_saved_materials(self, store):
        store.put_fit(record("1" * 32, material_id="Au", kind="library", library_material="Au"))
        store.put_fit(record("2" * 32, material_id="a" * 32, name="old"))
        store.put_fit(record("3" * 32, material_id="b" * 32, kind="curves", name="edited", base_fit_id="1" * 32))
        store.put_fit(record("4" * 32, material_id="a" * 32, name="new"))
        assert store.latest_fit("a" * 32).id == "4" * 32
        assert store.latest_fit("Au").id == "1" * 32
        assert store.latest_fit("c" * 32) is None
        rows = store.saved_materials()
        assert [(r.material_id, r.latest_fit_id, r.name) for r in rows] == [
            ("a" * 32, "4" * 32, "new"), ("b" * 32, "3" * 32, "edited"),
        ]

    def test_record_kind_checked(self):
        with pytest.raises(ValueError, match="`kind` must be one of"):
            record("6" * 32, kind="magic")

    def test_nan_refused(self, store):
        with pytest.raises(ValueError):
            store.put_fit(record("7" * 32, coverage=float("nan")))
        assert store.get_fit("7" * 32) is None

    def test_versions_and_expected_version(self, store):
        m = "v" * 32
        assert store.material_version(m) == 0
        first = store.put_fit(record("1" * 32, material_id=m, kind="curves"), expected_version=0)
        with pytest.raises(StoreConflict, match="at version 1.*not the expected version 0") as refused:
            store.put_fit(record("2" * 32, material_id=m, kind="curves"), expected_version=0)
        assert refused.value.version == 1 and refused.value.latest_fit_id == first.id
        assert store.get_fit("2" * 32) is None  # refused: nothing stored
        # The same save retried (its answer lost): answered, not logged twice.
        assert store.put_fit(first, expected_version=0) == first and store.material_version(m) == 1
        store.put_fit(record("2" * 32, material_id=m, kind="curves"), expected_version=1)
        store.put_fit(first)  # no expectation: the next version, whatever came before
        assert store.material_version(m) == 3 and store.latest_fit(m) == first
        (row,) = store.saved_materials()
        assert (row.version, row.latest_fit_id) == (3, first.id)

    def test_drafts_are_not_saves(self, store):
        draft = store.put_fit(record("3" * 32, material_id="d" * 32, kind="curves"), save=False)
        assert store.get_fit(draft.id) == draft
        assert store.latest_fit("d" * 32) is None and store.material_version("d" * 32) == 0
        assert store.saved_materials() == []

    def test_pages_follow_the_save_order(self, store):
        for i in range(7):
            store.put_fit(record(f"{i:032x}", material_id=f"{i + 50:032x}", name=f"m{i}"))
        names, cursor = [], None
        for _ in range(5):
            page = store.material_page(cursor, 3)
            names += [r.name for r in page.rows]
            cursor = page.next_cursor
            if cursor is None:
                break
        assert names == [f"m{i}" for i in range(7)]
        assert store.latest_fit_ids([f"{i + 50:032x}" for i in (0, 6)] + ["x"]) == {
            f"{50:032x}": f"{0:032x}", f"{56:032x}": f"{6:032x}"}

    def test_ping_writable_check(self, store):
        store.ping()
        assert store.writable() is None
        store.check()

    def test_nul_in_a_name_is_stored(self, store):
        saved = store.put_fit(record("8" * 32, material_id="n" * 32, name="a\x00b"))
        assert store.get_fit(saved.id).name == "a\x00b"  # the record keeps it exactly
        assert store.saved_materials()[0].name == "a\ufffdb"  # the summary shows it


class TestSQLiteStore:
    def test_wal_mode(self, tmp_path):
        store = SQLiteStore(tmp_path / "store.sqlite3")
        with sqlite3.connect(store.path) as connection:
            assert connection.execute("PRAGMA journal_mode").fetchone()[0] == "wal"
        store.close()

    def test_store_from_before_the_save_log_is_read(self, tmp_path):
        import sqlite3

        path = tmp_path / "old.sqlite"
        old = sqlite3.connect(path)
        old.executescript(
            "CREATE TABLE fits (id TEXT PRIMARY KEY, kind TEXT NOT NULL, material_id TEXT NOT NULL,"
            " created_at REAL NOT NULL, record TEXT NOT NULL);"
        )
        for i, name in ((1, "old"), (2, "new")):
            r = record(str(i) * 32, material_id="a" * 32, name=name, created_at=float(i))
            old.execute("INSERT INTO fits VALUES (?, ?, ?, ?, ?)",
                        (r.id, r.kind, r.material_id, r.created_at, r.to_json()))
        old.commit()
        old.close()
        store = SQLiteStore(path)
        try:
            assert store.latest_fit("a" * 32).name == "new"
            assert [m.name for m in store.saved_materials()] == ["new"]
        finally:
            store.close()

    def test_survives_reopen(self, tmp_path):
        path = tmp_path / "s.sqlite3"
        first = SQLiteStore(path)
        first.put_fit(record("5" * 32))
        first.close()
        second = SQLiteStore(path)
        assert second.get_fit("5" * 32).name == "gold"
        second.check()
        second.close()

    def test_check_reports_damage(self, tmp_path):
        path = tmp_path / "broken.sqlite3"
        path.write_bytes(b"not a database" * 100)
        with pytest.raises(sqlite3.DatabaseError):
            SQLiteStore(path)

    def test_closed_store_refuses(self, store):
        store.close()
        with pytest.raises((RuntimeError, sqlite3.ProgrammingError)):
            store.check()

