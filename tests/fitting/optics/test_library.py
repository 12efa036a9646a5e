"""fitting.optics.library: the 22 built-in conductors."""

import pytest

from fitting.optics.library import LIBRARY, LIBRARY_NAMES, library_material


class TestLibrary:
    def test_all_22_with_citations(self):
        assert len(LIBRARY_NAMES) == 22
        for name in LIBRARY_NAMES:
            nk = library_material(name)
            lo, hi = nk.wavelength_range_nm
            assert lo <= 360.0 + 1e-6 or name in ("K", "Na"), name
            assert hi >= 830.0 - 1e-6 or name == "Nb"
            assert LIBRARY[name][2] in nk.source and len(nk.source) > 40
            assert nk.name == name

    def test_unknown_name(self):
        with pytest.raises(ValueError, match="`material` must be one of"):
            library_material("Unobtainium")
