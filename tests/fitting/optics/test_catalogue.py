"""The conductor catalogue: built from the shelf, current, searched by name and symbol."""

from __future__ import annotations

import numpy as np
import pytest

from fitting.cli.main import main
from fitting.optics.catalogue import (
    CATALOGUE_PATH,
    catalogue,
    catalogue_header,
    catalogue_material,
    SUGGESTIONS,
    resolve_material,
    search_catalogue,
)
from fitting.optics.library import LIBRARY, library_material
from fitting.optics.names import BOOK_NAMES, CATEGORIES, page_name


@pytest.mark.slow  # reads every page of two shelves: about 5 s
def test_the_committed_catalogue_is_what_the_shelf_gives(capsys):
    from fitting.batch.catalogue import catalogue_json

    assert CATALOGUE_PATH.read_bytes() == catalogue_json(), "run: python -m fitting catalogue"
    assert main(["catalogue", "--check"]) == 0
    assert "is current" in capsys.readouterr().err


def test_a_stale_file_is_reported(tmp_path, capsys, monkeypatch):
    import fitting.batch.catalogue as build

    stale = tmp_path / "catalogue.json"
    stale.write_text("{}")
    monkeypatch.setattr(build, "build_catalogue", lambda: {"materials": []})
    assert main(["catalogue", "--check", "-o", str(stale)]) == 1
    assert "out of date" in capsys.readouterr().err
    assert main(["catalogue", "-o", str(stale)]) == 0 and main(["catalogue", "--check", "-o", str(stale)]) == 0


class TestCatalogue:
    def test_several_hundred_opaque_conductors(self):
        entries = catalogue()
        assert len(entries) >= 300
        assert {e["category"] for e in entries.values()} <= set(CATEGORIES)
        assert {"metal", "alloy", "nitride", "carbide"} <= {e["category"] for e in entries.values()}
        header = catalogue_header()
        assert header["shelves"] == ["main", "other"] and header["rule"]["min_coverage"] == 0.9
        # Every book has exactly one preferred page; the paper's library keeps its ids and pages.
        books = {}
        for entry in entries.values():
            books.setdefault(entry["book"], []).append(entry["preferred"])
        assert all(flags.count(True) == 1 for flags in books.values())
        for name, page in LIBRARY.items():
            assert entries[name]["page"] == "/".join(page) and entries[name]["preferred"]

    def test_every_page_is_opaque_and_covers_the_visible_range(self):
        rule = catalogue_header()["rule"]
        wavelength = np.arange(rule["opaque_range_nm"][0], rule["opaque_range_nm"][1] + 1, 5.0)
        for material_id in ("Ti.Johnson", "TiN.Schnabel", "stainless-steel.Karlsson-austenitic"):
            nk = catalogue_material(material_id)
            k = np.interp(wavelength, nk.wavelength_nm, nk.k)
            assert np.all(wavelength / (4 * np.pi * k) <= rule["absorption_depth_max_nm"])
            assert catalogue()[material_id]["coverage"] >= rule["min_coverage"]
        assert "SiO2" not in {e["book"] for e in catalogue().values()}  # glass is not a conductor

    @pytest.mark.parametrize(
        "query, book",
        [
            ("gold", "Au"),
            ("titanium", "Ti"),
            ("stainless", "stainless_steel"),
            ("brass", "Cu-Zn"),
            ("aluminium", "Al"),
            ("aluminum", "Al"),
            ("TiN", "TiN"),
            ("Cu", "Cu"),
            ("platinum", "Pt"),
            ("zinc", "Zn"),
            ("steel", "stainless_steel"),
            ("Ti", "Ti"),
        ],
    )
    def test_the_expected_entry_comes_first(self, query, book):
        found = search_catalogue(query)
        assert found[0]["book"] == book and found[0]["preferred"]

    def test_names_rank_before_descriptions_and_citations_are_not_searched(self):
        ti = search_catalogue("Ti")
        books = [e["book"] for e in ti]
        assert "Ni-Fe" not in books  # an author is called Tikuišis: not a match
        assert books.index("TiN") > max(i for i, b in enumerate(books) if b == "Ti")
        assert search_catalogue("johnson christy") == []
        assert search_catalogue("Cu")[0]["book"] == "Cu" and "Be" not in [e["book"] for e in search_catalogue("Cu")]
        assert [e["name"] for e in search_catalogue("brass")][:3] == ["brass 70/30", "brass 85/15", "brass 90/10"]
        assert len(search_catalogue("")) == len(catalogue())

    def test_names_and_symbols_resolve_in_any_case(self):
        assert {resolve_material(t) for t in ("gold", "GOLD", "au", "Au", " gold ", "main/Au/Johnson")} == {"Au"}
        assert resolve_material("aluminum") == resolve_material("Aluminium") == "Al"
        assert catalogue()[resolve_material("titanium")]["preferred"]
        assert resolve_material("ti.johnson") == "Ti.Johnson"
        assert catalogue_material("gold") is library_material("Au")
        assert catalogue_material("brass 85/15").source.startswith("refractiveindex.info other/Cu-Zn/")

    @pytest.mark.parametrize("bad", ["", "   ", "unobtainium", None, 3])
    def test_an_unknown_name_is_refused_naming_the_argument(self, bad):
        with pytest.raises(ValueError, match="`material`"):
            resolve_material(bad)

    def test_a_book_s_name_gives_its_preferred_page(self):
        """A book whose pages are named apart ("stainless steel, austenitic", "..., ferritic") by its own name."""
        assert resolve_material("stainless steel") == resolve_material("Stainless  Steel") == resolve_material("steel")
        assert catalogue()[resolve_material("stainless steel")]["preferred"]
        assert resolve_material("brass") == resolve_material("brass 70/30") == "CuZn"

    def test_a_refusal_names_the_best_matches(self):
        """A name that is not quite one is refused with what the search finds first: for the name, for it
        less a word, else the names nearest in spelling; nothing when nothing is near."""
        with pytest.raises(ValueError) as refused:
            resolve_material("stainless steel 316")
        message = str(refused.value)
        assert message.startswith("`material` must name a conductor of the library")
        assert message.endswith(
            "; did you mean stainless-steel.Karlsson-austenitic (stainless steel, austenitic), "
            "stainless-steel.Karlsson-ferritic (stainless steel, ferritic)?"
        )
        titan = str(pytest.raises(ValueError, resolve_material, "titan").value)
        suggestions = titan.split("; did you mean ")[1].removesuffix("?").split("), ")
        assert len(suggestions) == SUGGESTIONS and "Ti.Palm (titanium" in suggestions
        for suggestion in suggestions:
            identifier = suggestion.split(" (")[0]
            assert resolve_material(identifier) == identifier  # each suggestion resolves as given
        assert str(pytest.raises(ValueError, resolve_material, "titanum").value).endswith(
            "; did you mean Ti.Palm (titanium)?"  # the preferred page of the name spelt nearest
        )
        assert "did you mean" not in str(pytest.raises(ValueError, resolve_material, "unobtainium").value)

    def test_a_book_without_a_name_is_refused(self):
        with pytest.raises(ValueError, match="`book` 'Xx' has no common name"):
            page_name("Xx", "page")
        assert page_name("Cu-Zn", "Querry-Cu70Zn30") == "brass 70/30"
        assert page_name("Au", "Johnson") == BOOK_NAMES["Au"].name == "gold"


def test_the_command_line_takes_names(capsys):
    assert main(["library", "stainless"]) == 0
    first = capsys.readouterr().out.splitlines()[0]
    assert first.startswith("stainless-steel.Karlsson-austenitic") and "stainless steel, austenitic" in first
