"""
fitting.optics.bounded.parse_number and the readers (item 10):
numbers are ASCII decimal (Python's float also reads full-width and Arabic
digits and ``6_00``); a CSV of exactly the row limit is read.
"""

from __future__ import annotations

import pytest

from fitting.optics.bounded import csv_rows_bounded, is_number, parse_number
from fitting.optics.readers import read_nk

NOT_NUMBERS = ["４００", "٤٠٠", "۴۰۰", "6_00", "1_0.5", "0x10", "", " ", "1e", "--1", "१२"]
NUMBERS = {"400": 400.0, "-1.5e3": -1500.0, " .5 ": 0.5, "+2.": 2.0, "1E-2": 0.01}


class TestParseNumber:
    @pytest.mark.parametrize("text", NOT_NUMBERS)
    def test_refused(self, text):
        assert not is_number(text)
        with pytest.raises(ValueError, match=r"`x` must be a number in ASCII digits, got"):
            parse_number(text, "`x`")

    @pytest.mark.parametrize("text, value", NUMBERS.items())
    def test_read(self, text, value):
        assert parse_number(text, "`x`") == value

    def test_non_finite_words_pass_to_the_finiteness_checks(self):
        assert parse_number("inf", "`x`") == float("inf")


class TestReaders:
    @pytest.mark.parametrize("bad", ["４００", "٤٠٠", "6_00"])
    def test_csv(self, bad):
        text = f"wavelength_nm,n,k\n{bad},1,1\n500,1,1\n600,1,1\n"
        with pytest.raises(ValueError, match="CSV line 2 must hold three numbers"):
            read_nk(text, "csv")

    @pytest.mark.parametrize("bad", ["４００", "٤٠٠", "6_00"])
    def test_yaml_table(self, bad):
        text = f"DATA:\n  - type: tabulated nk\n    data: |\n      0.4 1 1\n      {bad} 1 1\n"
        with pytest.raises(ValueError, match="rows of numbers"):
            read_nk(text, "yaml")

    def test_yaml_plain_scalar_with_underscore(self):
        text = "DATA:\n  - type: formula 2\n    wavelength_range: 0.3 1\n    coefficients: 6_00\n"
        with pytest.raises(ValueError, match="without `_`|must be numbers"):
            read_nk(text, "yaml")
        with pytest.raises(ValueError, match=r"YAML number '6_00' must be written without `_`"):
            read_nk("DATA:\n  - type: formula 2\n    wavelength_range: [6_00, 900]\n", "yaml")


class TestRowLimit:
    @pytest.mark.parametrize("ending", ["\n", "", "\n\n\n", "\r\n"])
    def test_exactly_the_limit_is_read(self, ending):
        rows = "\n".join(f"{400 + i},1,1" for i in range(10))
        assert len(csv_rows_bounded("wavelength_nm,n,k\n" + rows + ending, max_rows=11)) == 11

    def test_one_past_the_limit_is_refused(self):
        rows = "\n".join(f"{400 + i},1,1" for i in range(11))
        with pytest.raises(ValueError, match="at most 11 lines, got 12"):
            csv_rows_bounded("wavelength_nm,n,k\n" + rows + "\n", max_rows=11)

    def test_read_nk_csv_at_its_max_samples(self):
        rows = "".join(f"{400 + i},0.2,3\n" for i in range(8))
        assert read_nk("wavelength_nm,n,k\n" + rows, "csv", max_samples=8).wavelength_nm.size == 8
