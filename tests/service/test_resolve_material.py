"""
Which material a save of edited curves goes to, when another save of the
same name lands between the name's lookup and the choice of a new id (two
first saves at once, on one replica or on two): the same material, never
a second one of that name (which would split the versions and let two
``expected_version=0`` saves both win).
"""

from __future__ import annotations

import pytest

from service.jobs.common import content_address
from service.jobs.materials import resolve_material
from service.store import FitRecord, SQLiteStore

POSTGRES = pytest.param("postgresql", marks=[pytest.mark.xdist_group("postgres"), pytest.mark.slow])


def curves_record(fit_id: str, material_id: str, name: str) -> FitRecord:
    return FitRecord(id=fit_id, kind="curves", material_id=material_id, name=name, source="edit",
                     material={"name": name, "coefficients": {"F0": [[0.5]] * 3}}, metrics={"x": 1.0})


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
