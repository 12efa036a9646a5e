"""
The store contract, run against both stores (SQLite and PostgreSQL on a
real server the tests start): content-addressed, write-once records that
survive reopening, the save log, versions; then what only SQLite has.
"""

from __future__ import annotations

import sqlite3

import pytest

from service.store import SCHEMA_VERSION, FitRecord, NameTaken, SQLiteStore, Store, StoreConflict

POSTGRES = pytest.param("postgresql", marks=[pytest.mark.xdist_group("postgres"), pytest.mark.slow])


def record(fit_id: str, material_id: str = "m" * 32, kind: str = "nk", name: str = "gold", **extra) -> FitRecord:
    return FitRecord(
        id=fit_id,
        kind=kind,
        material_id=material_id,
        name=name,
        source="lab",
        material={"name": name, "coefficients": {"F0": [[0.5]] * 3}},
        metrics={"x": 1.0},
        **extra,
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

    def test_metrics_set_after_the_save_and_nothing_else(self, store):
        import dataclasses

        saved = store.put_fit(dataclasses.replace(record("1" * 32), metrics={"evaluated": False}))
        stored = store.set_metrics("1" * 32, {"figure": {"delta_E_mean": 0.5}})
        assert stored == store.get_fit("1" * 32)
        assert stored.metrics == {"figure": {"delta_E_mean": 0.5}}
        assert {**stored.__dict__, "metrics": None} == {**saved.__dict__, "metrics": None}
        assert store.material_version(saved.material_id) == 1  # not a save
        assert store.set_metrics("2" * 32, {}) is None

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
            ("a" * 32, "4" * 32, "new"),
            ("b" * 32, "3" * 32, "edited"),
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

    def test_a_repeat_is_not_a_version(self, store):
        m = "r" * 32
        first = store.put_fit(record("1" * 32, material_id=m, kind="curves", name="A"))
        for _ in range(1000):
            assert store.put_fit(record("1" * 32, material_id=m, kind="curves", name="A")) == first
        assert store.material_version(m) == 1 and len(store.material_versions(m, None, 10)) == 1
        store.put_fit(record("2" * 32, material_id=m, kind="curves", name="A"))
        store.put_fit(first)  # an earlier state saved again: a change, so a version
        assert store.material_version(m) == 3

    def test_versions_per_material_are_bounded(self, store, monkeypatch):
        from service.store import StoreFull, queries

        monkeypatch.setattr(queries, "MAX_VERSIONS_PER_MATERIAL", 3)
        m = "b" * 32
        for i in range(3):
            store.put_fit(record(f"{i + 1:032x}", material_id=m, kind="curves", name="A"))
        with pytest.raises(StoreFull, match="has 3 versions, the most one material keeps"):
            store.put_fit(record(f"{9:032x}", material_id=m, kind="curves", name="A"))
        assert store.material_version(m) == 3 and store.get_fit(f"{9:032x}") is None
        assert store.put_fit(record(f"{3:032x}", material_id=m, kind="curves", name="A")).id == f"{3:032x}"

    def test_a_stale_save_does_not_undo_a_rename_or_a_delete(self, store):
        m = "s" * 32
        first = store.put_fit(record("1" * 32, material_id=m, kind="curves", name="A"))
        store.rename_material(m, "B")
        # An editor opened at version 1 (as "A") saves: it would rename the material back.
        with pytest.raises(StoreConflict, match="renamed 'B' since version 1") as renamed:
            store.put_fit(record("2" * 32, material_id=m, kind="curves", name="A"), expected_version=1)
        assert renamed.value.version == 1 and store.get_fit("2" * 32) is None
        store.put_fit(record("2" * 32, material_id=m, kind="curves", name="B"), expected_version=1)
        store.delete_material(m)
        with pytest.raises(StoreConflict, match="moved to the bin") as binned:
            store.put_fit(record("3" * 32, material_id=m, kind="curves", name="B"), expected_version=2)
        assert binned.value.latest_fit_id == "2" * 32 and store.material(m).deleted_at is not None
        # Without an expectation the save restores it (the service's answer says so).
        store.put_fit(record("3" * 32, material_id=m, kind="curves", name="B"))
        assert store.material(m).deleted_at is None and store.material_version(m) == 3
        assert store.latest_fit(m).id == "3" * 32 and first.id != "3" * 32

    def test_drafts_are_not_saves(self, store):
        draft = store.put_fit(record("3" * 32, material_id="d" * 32, kind="curves"), save=False)
        assert store.get_fit(draft.id) == draft
        assert store.latest_fit("d" * 32) is None and store.material_version("d" * 32) == 0
        assert store.saved_materials() == []

    def test_an_nk_record_is_kept_once_and_expires_with_its_drafts(self, store):
        # Drafts on an inline n, k refer to it (``nk_id``); it is stored once.
        nk = {"wavelength_nm": [400.0, 500.0, 600.0], "n": [0.2, 0.3, 0.4], "k": [3.0, 2.5, 2.0]}
        other = {"wavelength_nm": [400.0, 700.0], "n": [1.0, 1.1], "k": [0.5, 0.6]}
        drafts = [
            store.put_fit(record(f"{i:032x}", kind="curves", nk_id="e" * 32, created_at=100.0 + i), save=False, nk=nk)
            for i in range(3)
        ]
        assert store.get_nk("e" * 32) == nk and store.get_nk("f" * 32) is None
        assert [store.get_fit(d.id) for d in drafts] == drafts and drafts[0].nk is None
        assert store.saved_materials() == []  # neither listed nor a material
        saved = store.put_fit(record("a" * 32, kind="curves", nk_id="d" * 32, created_at=50.0), nk=other)
        # Past their time to live two drafts go; the third still refers to the n, k.
        assert store.expire_drafts(older_than=101.5, max_bytes=10**9) == 2
        assert store.get_nk("e" * 32) == nk and store.get_fit(drafts[2].id) == drafts[2]
        # The quota counts the draft with its n, k record: one byte short, both go.
        draft_bytes = len(drafts[2].to_json()) + len(
            '{"wavelength_nm":[400.0,500.0,600.0],"n":[0.2,0.3,0.4],"k":[3.0,2.5,2.0]}'
        )
        assert store.expire_drafts(older_than=0.0, max_bytes=draft_bytes) == 0
        assert store.expire_drafts(older_than=0.0, max_bytes=draft_bytes - 1) == 1
        assert store.get_fit(drafts[2].id) is None and store.get_nk("e" * 32) is None
        # A saved fit's n, k record is never removed.
        assert store.get_fit(saved.id) == saved and store.get_nk("d" * 32) == other
        with pytest.raises(TypeError, match="needs the fit's `nk_id`"):
            store.put_fit(record("b" * 32), nk=nk)

    def test_a_draft_a_saved_fit_starts_from_is_kept_with_its_own_base(self, store):
        # Draft 1 starts from draft 0; the saved fit "s" starts from draft 1; draft 2 is alone.
        drafts = [
            store.put_fit(
                record(
                    f"{i:032x}", kind="curves", created_at=float(i), base_fit_id=f"{i - 1:032x}" if i == 1 else None
                ),
                save=False,
            )
            for i in range(3)
        ]
        saved = store.put_fit(record("5" * 32, kind="curves", name="kept", base_fit_id=drafts[1].id))
        assert store.expire_drafts(older_than=10.0**12, max_bytes=0) == 1  # only the one nothing refers to
        assert [store.get_fit(d.id) for d in drafts] == [drafts[0], drafts[1], None]
        assert store.get_fit(saved.id) == saved
        # A draft on a kept draft is a draft like any other.
        store.put_fit(record("6" * 32, kind="curves", base_fit_id=drafts[1].id), save=False)
        assert store.expire_drafts(older_than=10.0**12, max_bytes=0) == 1 and store.get_fit("6" * 32) is None

    def test_a_draft_a_link_keeps_outlives_its_time_to_live_but_not_the_quota(self, store):
        import time

        linked, other = (store.put_fit(record(f"{i:032x}", kind="curves", created_at=1.0), save=False) for i in (1, 2))
        until = time.time() + 3600
        assert store.keep_draft(linked.id, until) == until
        assert store.keep_draft(linked.id, until - 10) == until  # never shortened
        assert store.expire_drafts(older_than=10.0, max_bytes=10**9) == 1
        assert store.get_fit(linked.id) == linked and store.get_fit(other.id) is None
        saved = store.put_fit(record("5" * 32, kind="curves", name="s", base_fit_id=linked.id))
        assert store.keep_draft(saved.id, until) is None and store.keep_draft(linked.id, until) is None
        with pytest.raises(LookupError, match="not found"):
            store.keep_draft("7" * 32, until)
        # Past the quota, drafts no link keeps go first, then the linked ones.
        loose = store.put_fit(record("8" * 32, kind="curves", created_at=time.time()), save=False)
        kept = store.put_fit(record("9" * 32, kind="curves", created_at=1.0), save=False)
        store.keep_draft(kept.id, until)
        assert store.expire_drafts(older_than=0.0, max_bytes=len(kept.to_json())) == 1
        assert store.get_fit(kept.id) == kept and store.get_fit(loose.id) is None
        assert store.expire_drafts(older_than=0.0, max_bytes=0) == 1 and store.get_fit(kept.id) is None

    def test_an_nk_record_already_stored_is_not_written_again(self, store):
        # Content-addressed: a live step on a stored inline n, k makes no JSON of it (0.6 MB at
        # 20,000 samples), and what was stored first stays.
        class Read(dict):
            reads = 0

            def __getitem__(self, key):
                self.reads += 1
                return super().__getitem__(key)

        nk = Read({"wavelength_nm": [400.0, 500.0], "n": [0.2, 0.3], "k": [3.0, 2.5]})
        store.put_fit(record("1" * 32, kind="curves", nk_id="c" * 32), save=False, nk=nk)
        assert nk.reads == 3 and store.get_nk("c" * 32) == nk
        again = store.put_fit(record("2" * 32, kind="curves", nk_id="c" * 32), save=False, nk=nk)
        assert nk.reads == 3 and again.nk_id == "c" * 32 and store.get_nk("c" * 32) == nk

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
            f"{50:032x}": f"{0:032x}",
            f"{56:032x}": f"{6:032x}",
        }

    def test_ping_writable_check(self, store):
        store.ping()
        assert store.writable() is None
        store.check()

    def test_nul_in_a_name_is_stored(self, store):
        saved = store.put_fit(record("8" * 32, material_id="n" * 32, name="a\x00b"))
        assert store.get_fit(saved.id).name == "a\x00b"  # the record keeps it exactly
        assert store.saved_materials()[0].name == "a\ufffdb"  # the summary shows it


class TestMaterialsManaged:
    """Rename, the bin, versions and the listing's filters, on both stores."""

    def test_rename_is_not_a_save_and_names_are_unique(self, store):
        a, b = "a" * 32, "b" * 32
        store.put_fit(record("1" * 32, material_id=a, kind="curves", name="A"))
        store.put_fit(record("2" * 32, material_id=b, kind="curves", name="B"))
        renamed = store.rename_material(a, "A2")
        assert (renamed.name, renamed.version, renamed.latest_fit_id) == ("A2", 1, "1" * 32)
        assert store.find_material("curves", "A2") == a and store.find_material("curves", "A") is None
        with pytest.raises(NameTaken) as taken:
            store.rename_material(a, "B")
        assert taken.value.status == 409 and "B" in str(taken.value)
        assert store.material(a).name == "A2"  # refused: nothing changed
        with pytest.raises(LookupError):
            store.rename_material("c" * 32, "C")
        store.put_fit(record("3" * 32, material_id="Au", kind="library", library_material="Au"))
        with pytest.raises(ValueError, match="built-in"):
            store.rename_material("Au", "gold")
        # The record keeps the name it was saved under; the next save names the material.
        assert store.get_fit("1" * 32).name == "A"
        store.put_fit(record("4" * 32, material_id=a, kind="curves", name="A2"))
        assert (store.material(a).name, store.material(a).version) == ("A2", 2)

    def test_a_look_alike_name_is_refused_naming_the_material(self, store):
        a, b, c = "a" * 32, "b" * 32, "c" * 32
        store.put_fit(record("1" * 32, material_id=a, kind="curves", name="Brass mix"))
        store.put_fit(record("2" * 32, material_id=b, kind="curves", name="warm"))
        # Case, a Cyrillic letter, full-width forms, a zero-width space, "rn" for "m": one skeleton.
        for name in ("brass mix", "Br\u0430ss mix", "\uff22rass mix", "Bra\u200bss mix", "Brass  mix", "Brass rnix"):
            with pytest.raises(NameTaken, match=f"looks the same as 'Brass mix', the name of saved material {a}"):
                store.put_fit(record("3" * 32, material_id=c, kind="curves", name=name))
            with pytest.raises(NameTaken, match=f"looks the same as 'Brass mix', the name of saved material {a}"):
                store.rename_material(b, name)
            # The same refusal, asked ahead of a save (before its fit): the store's own rule.
            assert store.name_clash(name, c).startswith(f"`name` {name!r} looks the same as 'Brass mix'")
        assert store.name_clash("Brass mix", c) is None  # the very name: the save goes to that material
        assert store.name_clash("warm 2", c) is None
        assert store.material(c) is None and store.material(b).name == "warm"
        # Its own material may take a look-alike spelling; another name is free.
        assert store.name_clash("brass mix", a) is None
        assert store.rename_material(a, "brass mix").name == "brass mix"
        store.put_fit(record("4" * 32, material_id=c, kind="curves", name="Brass mix 2"))
        store.delete_material(a)  # the bin keeps the name
        with pytest.raises(NameTaken, match="in the bin"):
            store.rename_material(b, "BRASS MIX")

    def test_delete_is_a_bin_and_nothing_is_lost(self, store):
        a, b = "a" * 32, "b" * 32
        first = store.put_fit(record("1" * 32, material_id=a, kind="curves", name="A"))
        store.put_fit(record("2" * 32, material_id=a, kind="curves", name="A"))
        store.put_fit(record("5" * 32, material_id=b, kind="curves", name="B"))
        gone = store.delete_material(a)
        assert gone.deleted_at is not None and store.delete_material(a).deleted_at == gone.deleted_at
        assert [r.material_id for r in store.material_page(None, 10).rows] == [b]
        assert [r.material_id for r in store.material_page(None, 10, deleted=True).rows] == [a]
        # Its fits, saves and versions are all still there.
        assert store.get_fit(first.id) == first and store.latest_fit(a).id == "2" * 32
        assert [v.version for v in store.material_versions(a, None, 10)] == [2, 1]
        assert store.restore_material(a).deleted_at is None
        assert [r.material_id for r in store.material_page(None, 10).rows] == [a, b]
        # A save of a material in the bin takes it out.
        store.delete_material(b)
        store.put_fit(record("6" * 32, material_id=b, kind="curves", name="B"))
        assert store.material(b).deleted_at is None and store.material(b).version == 2
        with pytest.raises(LookupError):
            store.delete_material("c" * 32)

    def test_versions_newest_first_by_page(self, store):
        m = "a" * 32
        for i in (1, 2, 3, 1, 4):  # an undo then save of 1: a version of its own
            store.put_fit(record(f"{i:032x}", material_id=m, kind="curves", name="A"))
        versions = store.material_versions(m, None, 3)
        assert [(v.version, v.fit_id[-1]) for v in versions] == [(5, "4"), (4, "1"), (3, "3")]
        assert versions[0].record == store.get_fit(f"{4:032x}") and versions[0].saved_at > 0
        older = store.material_versions(m, versions[-1].version, 3)
        assert [(v.version, v.fit_id[-1]) for v in older] == [(2, "2"), (1, "1")]
        assert store.version_fit(m, 2).id == f"{2:032x}" and store.version_fit(m, 6) is None
        assert store.material_versions("b" * 32, None, 3) == []

    def test_listing_by_kind_and_query(self, store):
        store.put_fit(record("1" * 32, material_id="a" * 32, kind="curves", name="Warm 100%_gold"))
        store.put_fit(record("2" * 32, material_id="b" * 32, kind="nk", name="upload"))
        store.put_fit(record("3" * 32, material_id="Au", kind="library", library_material="Au"))
        names = lambda page: [r.name for r in page.rows]  # noqa: E731
        assert names(store.material_page(None, 10)) == ["Warm 100%_gold", "upload"]
        assert names(store.material_page(None, 10, ("curves",))) == ["Warm 100%_gold"]
        assert names(store.material_page(None, 10, ("nk",))) == ["upload"]
        assert names(store.material_page(None, 10, ("curves", "nk"), query="WARM")) == ["Warm 100%_gold"]
        # LIKE's wildcards are literal in a query.
        assert names(store.material_page(None, 10, query="100%_")) == ["Warm 100%_gold"]
        assert names(store.material_page(None, 10, query="0_g")) == []
        assert names(store.material_page(None, 10, query="lab")) == ["Warm 100%_gold", "upload"]  # the source


class TestSQLiteStore:
    def test_wal_mode(self, tmp_path):
        store = SQLiteStore(tmp_path / "store.sqlite3")
        with sqlite3.connect(store.path) as connection:
            assert connection.execute("PRAGMA journal_mode").fetchone()[0] == "wal"
        store.close()

    def test_the_writable_probe_never_waits_for_another_writer_s_lock(self, tmp_path):
        import time

        store = SQLiteStore(tmp_path / "store.sqlite3")
        holder = sqlite3.connect(store.path, isolation_level=None)
        holder.execute("BEGIN IMMEDIATE")  # another process's long write transaction
        try:
            started = time.perf_counter()
            store.ping()
            assert store.writable() is None and time.perf_counter() - started < 1.0  # it waited 30 s
        finally:
            holder.execute("ROLLBACK")
            holder.close()
        store.put_fit(record("1" * 32))  # the probe left the saves' own wait for the lock as it was
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
            old.execute(
                "INSERT INTO fits VALUES (?, ?, ?, ?, ?)", (r.id, r.kind, r.material_id, r.created_at, r.to_json())
            )
        old.commit()
        old.close()
        store = SQLiteStore(path)
        try:
            assert store.latest_fit("a" * 32).name == "new"
            assert [m.name for m in store.saved_materials()] == ["new"]
        finally:
            store.close()

    def test_a_version_5_store_gets_name_keys_and_bases(self, tmp_path):
        path = tmp_path / "v5.sqlite3"
        store = SQLiteStore(path)
        store.put_fit(record("1" * 32, material_id="a" * 32, kind="curves", name="Brass mix"))
        store.put_fit(record("2" * 32, material_id="b" * 32, kind="curves", name="warm"))
        store.put_fit(record("9" * 32, kind="curves", created_at=1.0), save=False)
        store.put_fit(record("8" * 32, material_id="e" * 32, kind="curves", name="on a draft", base_fit_id="9" * 32))
        store.close()
        old = sqlite3.connect(path)  # back to version 5: no keys, and two look-alike names
        old.executescript(
            "DROP INDEX materials_by_name_key; ALTER TABLE materials DROP COLUMN name_key; "
            "DROP INDEX fits_by_base; ALTER TABLE fits DROP COLUMN base_fit_id; ALTER TABLE fits DROP COLUMN kept_until; "
            "DELETE FROM schema_migrations WHERE version >= 6; "
            "UPDATE materials SET name = 'brass mix' WHERE material_id = 'bbbbbbbbbbbbbbbbbbbbbbbbbbbbbbbb'"
        )
        old.close()
        store = SQLiteStore(path)
        try:
            assert store.migrated == (5, SCHEMA_VERSION)
            assert store.expire_drafts(older_than=10.0**12, max_bytes=0) == 0 and store.get_fit("9" * 32)
            store.put_fit(record("3" * 32, material_id="a" * 32, kind="curves", name="Brass mix"))
            store.put_fit(record("4" * 32, material_id="b" * 32, kind="curves", name="brass mix"))
            assert [store.material(m).version for m in ("a" * 32, "b" * 32)] == [2, 2]
            with pytest.raises(NameTaken, match="looks the same as"):
                store.put_fit(record("5" * 32, material_id="c" * 32, kind="curves", name="BRASS MIX"))
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
