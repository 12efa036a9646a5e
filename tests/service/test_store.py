"""The SQLite store: content-addressed, write-once records that survive reopening."""

from __future__ import annotations

import sqlite3

import pytest

from service.store import FitRecord, SQLiteStore, Store


def record(fit_id: str, material_id: str = "m" * 32, kind: str = "nk", name: str = "gold", **extra) -> FitRecord:
    return FitRecord(
        id=fit_id, kind=kind, material_id=material_id, name=name, source="lab",
        material={"name": name, "coefficients": {"F0": [[0.5]] * 3}}, metrics={"x": 1.0}, **extra,
    )


@pytest.fixture
def store(tmp_path):
    opened = SQLiteStore(tmp_path / "store.sqlite3")
    yield opened
    opened.close()


class TestSQLiteStore:
    def test_is_a_store(self, store):
        assert isinstance(store, Store)

    def test_wal_mode(self, store):
        with sqlite3.connect(store.path) as connection:
            assert connection.execute("PRAGMA journal_mode").fetchone()[0] == "wal"

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

    def test_record_kind_checked(self):
        with pytest.raises(ValueError, match="`kind` must be one of"):
            record("6" * 32, kind="magic")

    def test_nan_refused(self, store):
        with pytest.raises(ValueError):
            store.put_fit(record("7" * 32, coverage=float("nan")))
        assert store.get_fit("7" * 32) is None
