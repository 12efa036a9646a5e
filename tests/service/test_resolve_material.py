"""
Which material a save of edited curves goes to, when another save of the
same name lands between the name's lookup and the choice of a new id (two
first saves at once, on one replica or on two): the same material, never
a second one of that name (which would split the versions and let two
``expected_version=0`` saves both win); and when a rename gives the name to
another material in that moment, a 409 (names of edited materials are
unique), never two materials of one name.
"""

from __future__ import annotations

import pytest

from service.jobs.common import content_address
from service.jobs.materials import resolve_material
from service.store import FitRecord, NameTaken, SQLiteStore

POSTGRES = pytest.param("postgresql", marks=[pytest.mark.xdist_group("postgres"), pytest.mark.slow])


def curves_record(fit_id: str, material_id: str, name: str) -> FitRecord:
    return FitRecord(
        id=fit_id,
        kind="curves",
        material_id=material_id,
        name=name,
        source="edit",
        material={"name": name, "coefficients": {"F0": [[0.5]] * 3}},
        metrics={"x": 1.0},
    )


class StaleLookup:
    """A store whose name lookup answers as it did before a concurrent save committed."""

    def __init__(self, store) -> None:
        self._store = store

    def find_material(self, kind: str, name: str) -> None:
        return None

    def __getattr__(self, attribute: str):
        return getattr(self._store, attribute)


@pytest.fixture(params=["sqlite", POSTGRES])
def store(request, tmp_path):
    if request.param == "sqlite":
        opened = SQLiteStore(tmp_path / "store.sqlite3")
    else:
        from service.store.postgres import PostgresStore

        opened = PostgresStore(request.getfixturevalue("postgres_url"))
    yield opened
    opened.close()


@pytest.mark.parametrize("name", ["gold leaf", "nul\x00name"])
def test_saved_meanwhile_is_the_same_material(store, name):
    first = content_address("edited material", name)
    assert resolve_material(store, name) == first  # nothing saved yet: the name's address
    store.put_fit(curves_record("1" * 32, first, name))
    # The other save committed after this one's lookup: its material is this one's.
    assert resolve_material(StaleLookup(store), name) == first
    assert resolve_material(store, name) == first


def test_renamed_away_takes_the_next_address(store):
    first = content_address("edited material", "gold")
    store.put_fit(curves_record("1" * 32, first, "gold"))
    store.rename_material(first, "gilt")
    second = content_address("edited material", "gold", 1)
    assert resolve_material(store, "gold") == second
    assert resolve_material(StaleLookup(store), "gold") == second
    assert resolve_material(store, "gilt") == first


def test_a_rename_to_the_name_in_between_is_a_conflict(store):
    store.put_fit(curves_record("1" * 32, "m" * 32, "other"))
    chosen = resolve_material(store, "x")  # nothing is called "x" yet: a new material
    store.rename_material("m" * 32, "x")  # another user, before this save is written
    with pytest.raises(NameTaken, match="was just given to another saved material"):
        store.put_fit(curves_record("2" * 32, chosen, "x"))
    assert [m.material_id for m in store.saved_materials() if m.name == "x"] == ["m" * 32]
    assert store.get_fit("2" * 32) is None  # the refused save left nothing behind
    # Saved again, it goes to the material called "x" now.
    again = resolve_material(store, "x")
    assert again == "m" * 32
    assert store.put_fit(curves_record("3" * 32, again, "x")).material_id == "m" * 32
