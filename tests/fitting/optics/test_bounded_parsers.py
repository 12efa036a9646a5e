"""
The bounded parsers of fitting.optics.bounded and the readers built on
them (fitting.optics.readers): every hostile shape is refused with a ValueError
that names the limit, quickly and without building the hostile document.
"""

from __future__ import annotations

import json
import time
import tracemalloc

import numpy as np
import pytest

from fitting.optics.bounded import (
    MAX_DEPTH,
    MAX_EXCERPT_CHARS,
    MAX_SAMPLES,
    MAX_YAML_NODES,
    check_sample_count,
    csv_rows_bounded,
    excerpt,
    load_json_bounded,
    load_yaml_bounded,
)
from fitting.optics.readers import read_nk, read_nk_csv, read_nk_json, read_nk_yaml

GOOD_YAML = """\
REFERENCES: "P. B. Johnson and R. W. Christy. <i>Phys. Rev. B</i> 6, 4370 (1972)"
DATA:
  - type: tabulated nk
    data: |
        0.40 1.66 1.96
        0.50 0.97 1.87
        0.60 0.25 2.98
        0.70 0.16 3.95
"""


def billion_laughs(levels: int, fan_out: int) -> str:
    lines = ["a0: &a0 [lol]"]
    for level in range(1, levels):
        refs = ", ".join(f"*a{level - 1}" for _ in range(fan_out))
        lines.append(f"a{level}: &a{level} [{refs}]")
    return "\n".join(lines) + "\nDATA: []\n"


def bounded_run(call, *args):
    """Run ``call``; return (the ValueError, seconds, peak traced MiB)."""
    tracemalloc.start()
    start = time.perf_counter()
    try:
        with pytest.raises(ValueError) as error:
            call(*args)
    finally:
        seconds = time.perf_counter() - start
        peak = tracemalloc.get_traced_memory()[1] / 2**20
        tracemalloc.stop()
    return error.value, seconds, peak


class TestExcerpt:
    def test_short_values_are_shown_whole(self):
        assert excerpt("abc") == "'abc'"
        assert excerpt(1.5) == "1.5"

    def test_long_values_are_cut(self):
        text = excerpt("x" * 10_000)
        assert len(text) <= MAX_EXCERPT_CHARS and text.endswith("...")

    def test_non_printable_is_escaped(self):
        assert excerpt("\x00\u202e") == "'\\x00\\u202e'"


# The `seconds < ...` and `peak < ...` (MiB) checks in this module are the
# parsers' resource budgets (docs/security.md), not numerical tolerances; the
# `len(...) < 200` ones bound an error message's length.


class TestLoadYamlBounded:
    def test_reads_a_plain_document(self):
        assert load_yaml_bounded("a: [1, 2, {b: c}]") == {"a": [1, 2, {"b": "c"}]}

    @pytest.mark.parametrize("levels, fan_out", [(9, 9), (30, 2), (4, 1000)])
    def test_alias_bombs_are_refused_before_expansion(self, levels, fan_out):
        error, seconds, peak = bounded_run(load_yaml_bounded, billion_laughs(levels, fan_out))
        assert "aliases" in str(error)
        assert seconds < 2.0 and peak < 50

    def test_a_single_alias_is_refused(self):
        with pytest.raises(ValueError, match=r"aliases \(`\*x`\)"):
            load_yaml_bounded("a: &x 1\nb: *x\n")

    def test_merge_keys_are_refused(self):
        with pytest.raises(ValueError, match="merge keys"):
            load_yaml_bounded("a: {<<: {b: 1}, c: 2}")

    @pytest.mark.parametrize("opener, closer", [("[", "]"), ("{a: ", "}")])
    def test_deep_flow_nesting_is_refused(self, opener, closer):
        text = opener * 100_000 + closer * 100_000
        error, seconds, _ = bounded_run(load_yaml_bounded, text)
        assert f"at most {MAX_DEPTH} levels" in str(error) and seconds < 5.0

    def test_deep_block_nesting_is_refused(self):
        text = "".join("  " * i + "- \n" for i in range(200)) + "  " * 200 + "- x\n"
        with pytest.raises(ValueError, match="levels deep"):
            load_yaml_bounded(text)

    def test_depth_at_the_limit_is_read(self):
        text = "[" * MAX_DEPTH + "]" * MAX_DEPTH
        assert load_yaml_bounded(text) is not None

    def test_node_budget(self):
        text = "[" + ", ".join("1" for _ in range(MAX_YAML_NODES + 10)) + "]"
        with pytest.raises(ValueError, match=f"at most {MAX_YAML_NODES} nodes"):
            load_yaml_bounded(text)

    def test_syntax_errors_do_not_echo_the_input(self):
        secret = "q" * 5000
        with pytest.raises(ValueError, match="YAML is not valid") as error:
            load_yaml_bounded(f"a: [{secret}\n b: :")
        assert secret[:200] not in str(error.value) and len(str(error.value)) < 200

    def test_size_limit(self):
        with pytest.raises(ValueError, match="at most 100 characters"):
            load_yaml_bounded("a: " + "x" * 200, max_chars=100)


class TestLoadJsonBounded:
    def test_reads_json_and_a_bom(self):
        assert load_json_bounded(b'\xef\xbb\xbf{"a": [1, 2.5]}') == {"a": [1, 2.5]}

    @pytest.mark.parametrize("opener, closer", [("[", "]"), ('{"a":', "}"), ('[{"a":', "}]")])
    def test_deep_nesting_is_refused_before_parsing(self, opener, closer):
        text = opener * 100_000 + "1" + closer * 100_000
        error, seconds, _ = bounded_run(load_json_bounded, text)
        assert f"at most {MAX_DEPTH} levels deep" in str(error) and seconds < 2.0

    def test_brackets_inside_strings_do_not_count(self):
        text = json.dumps({"a": "[" * 1000, "b": '\\"[[[['})
        assert load_json_bounded(text)["a"] == "[" * 1000

    @pytest.mark.parametrize("literal", ["NaN", "Infinity", "-Infinity"])
    def test_non_finite_literals_are_refused(self, literal):
        with pytest.raises(ValueError, match=f"`{literal}` is not accepted"):
            load_json_bounded(f'{{"n": [1, {literal}]}}')

    def test_huge_integer_literal(self):
        with pytest.raises(ValueError, match="JSON is not valid"):
            load_json_bounded("[" + "9" * 100_000 + "]")

    def test_not_utf8(self):
        with pytest.raises(ValueError, match="UTF-8"):
            load_json_bounded(b'{"a": "\xff\xfe"}')

    def test_invalid_json_names_the_place(self):
        with pytest.raises(ValueError, match="line 1 column"):
            load_json_bounded('{"a": [1, 2')


class TestCsvRowsBounded:
    def test_reads_rows(self):
        assert csv_rows_bounded("a,b\n\n1,2\n") == [["a", "b"], ["1", "2"]]

    def test_too_many_lines(self):
        with pytest.raises(ValueError, match="at most 11 lines"):
            csv_rows_bounded("1,2,3\n" * 20, max_rows=11)

    def test_long_line_is_refused_before_splitting(self):
        with pytest.raises(ValueError, match="at most 1000 characters"):
            csv_rows_bounded("wavelength_nm,n,k\n" + "1" * 500_000 + ",1,1\n")

    def test_too_many_columns(self):
        with pytest.raises(ValueError, match="line 2 must have at most 16 columns"):
            csv_rows_bounded("a,b,c\n" + ",".join("1" * 40) + "\n")

    def test_quoted_field_spanning_the_file(self):
        with pytest.raises(ValueError):
            csv_rows_bounded('wavelength_nm,n,k\n"' + "1\n" * 2000)


class TestCheckSampleCount:
    def test_counts(self):
        assert check_sample_count(400.0, 800.0, 5.0, "r") == 81

    @pytest.mark.parametrize("lo, hi", [(0.0, 1e15), (1e6, 1e300)])
    def test_huge_ranges_are_refused(self, lo, hi):
        with pytest.raises(ValueError, match=f"at most {MAX_SAMPLES} are allowed"):
            check_sample_count(lo, hi, 5.0, "`wavelength_range`")

    @pytest.mark.parametrize("lo, hi", [(1.0, float("inf")), (float("nan"), 2.0), (3.0, 2.0)])
    def test_bad_ranges(self, lo, hi):
        with pytest.raises(ValueError, match="finite increasing"):
            check_sample_count(lo, hi, 5.0, "`wavelength_range`")


class TestReadNkYamlHostile:
    def test_good_file(self):
        nk = read_nk_yaml(GOOD_YAML)
        assert nk.wavelength_nm.tolist() == [400.0, 500.0, 600.0, 700.0]
        assert nk.source.startswith("P. B. Johnson") and "<i>" not in nk.source

    def test_alias_bomb_in_a_valid_looking_file(self):
        bomb = billion_laughs(9, 9).replace("DATA: []", "DATA:\n  - type: tabulated nk\n    data: *a8")
        error, seconds, peak = bounded_run(read_nk_yaml, bomb)
        assert "aliases" in str(error) and seconds < 2.0 and peak < 50

    @pytest.mark.parametrize(
        "value, kind",
        [
            ("12", "a number"),
            ("[a, b]", "a list"),
            ("{a: b}", "a map"),
            ("2020-01-02", "a date"),
            ("!!binary aGVsbG8=", "binary data"),
            ("true", "a boolean"),
        ],
    )
    def test_references_of_the_wrong_type(self, value, kind):
        text = GOOD_YAML.replace(GOOD_YAML.splitlines()[0], f"REFERENCES: {value}")
        with pytest.raises(ValueError, match=f"`REFERENCES` must be text, got {kind}"):
            read_nk_yaml(text)

    @pytest.mark.parametrize(
        "data, rule",
        [
            ("DATA: 5", "`DATA` must be a non-empty list"),
            ("DATA: {type: tabulated nk}", "`DATA` must be a non-empty list"),
            ("DATA: [5]", r"`DATA\[0\]` must be a map"),
            ("DATA: [{type: [1]}]", r"`DATA\[0\].type` must be text, got a list"),
            ("DATA: [{type: tabulated nk, data: [1, 2, 3]}]", "`data` must be text"),
            ("DATA: [{type: tabulated nk, data: 2020-01-01}]", "`data` must be text .*, got a date"),
            ("DATA: [{type: tabulated nk, data: 'a b c'}]", "rows of numbers, got 'a'"),
            ("DATA: [{type: formula x}]", "`formula 1`-`formula 9`"),
            ("DATA: [{type: formula 12, coefficients: 1, wavelength_range: 0.3 0.9}]", "1-9, got 12"),
            (
                "DATA: [{type: formula 2, coefficients: [1], wavelength_range: 0.3 0.9}]",
                "`coefficients` must be text of numbers, got a list",
            ),
            ("DATA: [{type: formula 2, coefficients: true, wavelength_range: 0.3 0.9}]", "got a boolean"),
            (
                "DATA: [{type: formula 2, coefficients: 0 1 0.1, wavelength_range: {a: 1}}]",
                "`wavelength_range` must be text of numbers, got a map",
            ),
            ("DATA: [{type: formula 2, coefficients: 0 1 0.1, wavelength_range: 0.9 0.3}]", "two increasing numbers"),
            ("DATA: [{type: formula 2, coefficients: 0 1 0.1, wavelength_range: nan 0.3}]", "two increasing numbers"),
            (
                "DATA: [{type: formula 2, coefficients: " + " ".join(["1"] * 500) + ", wavelength_range: 0.3 0.9}]",
                "at most 64 numbers",
            ),
            ("DATA: [" + ", ".join(["{type: tabulated k}"] * 40) + "]", "at most 16 entries"),
        ],
    )
    def test_malformed_entries(self, data, rule):
        with pytest.raises(ValueError, match=rule):
            read_nk_yaml(data)

    @pytest.mark.parametrize("wr", ["1000 1e12", "1e3 1e9", "2 1e300"])
    def test_huge_wavelength_range_is_refused_before_allocating(self, wr):
        text = f"DATA: [{{type: formula 2, coefficients: 0 1 0.1, wavelength_range: {wr}}}]"
        error, seconds, peak = bounded_run(read_nk_yaml, text)
        assert "samples" in str(error) and seconds < 1.0 and peak < 20

    def test_a_formula_over_the_visible_range_is_sampled(self):
        nk = read_nk_yaml("DATA: [{type: formula 2, coefficients: 0 1.03 0.006, wavelength_range: 0.2 2.0}]")
        assert nk.wavelength_nm[0] == pytest.approx(355.0) and np.all(nk.k == 0)

    @pytest.mark.parametrize("row", range(4))
    @pytest.mark.parametrize("literal", ["nan", "-inf", "Infinity", "1e999"])
    def test_non_finite_table_values_are_refused(self, row, literal):
        lines = GOOD_YAML.splitlines()
        parts = lines[4 + row].split()
        parts[row % 3] = literal
        lines[4 + row] = "        " + " ".join(parts)
        with pytest.raises(ValueError, match=rf"must be finite numbers, got .* in row {row + 1}"):
            read_nk_yaml("\n".join(lines))

    def test_unsorted_table_is_refused_not_reordered(self):
        text = GOOD_YAML.replace("0.60 0.25 2.98", "0.45 0.25 2.98")
        with pytest.raises(ValueError, match="strictly increasing, got 0.45 after 0.5 in row 3"):
            read_nk_yaml(text)

    def test_long_rows_and_many_rows(self):
        wide = "DATA: [{type: tabulated nk, data: '" + "1 " * 2000 + "'}]"
        with pytest.raises(ValueError, match="at most 1000 characters"):
            read_nk_yaml(wide)
        many = "DATA:\n  - type: tabulated n\n    data: |\n" + "      0.5 1\n" * (MAX_SAMPLES + 1)
        with pytest.raises(ValueError, match=f"at most {MAX_SAMPLES} rows"):
            read_nk_yaml(many)

    def test_long_references_are_cut_quickly(self):
        text = GOOD_YAML.replace(GOOD_YAML.splitlines()[0], "REFERENCES: '" + "<" * 1_000_000 + "'")
        start = time.perf_counter()
        nk = read_nk_yaml(text)
        assert time.perf_counter() - start < 2.0 and len(nk.source) <= 2000


class TestReadNkJsonHostile:
    def test_good_file(self):
        nk = read_nk_json('{"wavelength_nm": [400, 500.5], "n": [1, 2], "k": [0, 0.5], "name": "g"}')
        assert nk.name == "g" and nk.wavelength_nm.tolist() == [400.0, 500.5]

    @pytest.mark.parametrize(
        "field, bad, kind",
        [
            ("n", "[true, 1]", r"`n\[0\]` must be a number, got a boolean"),
            ("k", "[0, false]", r"`k\[1\]` must be a number, got a boolean"),
            ("wavelength_nm", '[400, "500"]', r"`wavelength_nm\[1\]` must be a number, got str"),
            ("n", "[[1], [2]]", r"`n\[0\]` must be a number, got a list"),
            ("n", '{"a": 1}', "`n` must be a list of numbers, got a map"),
            ("k", "null", "`k` must be a list of numbers, got null"),
            ("n", "[1, 1e999]", "`n` must be finite"),
        ],
    )
    def test_wrong_types(self, field, bad, kind):
        view = {"wavelength_nm": "[400, 500]", "n": "[1, 2]", "k": "[0, 0]", field: bad}
        text = "{" + ", ".join(f'"{key}": {value}' for key, value in view.items()) + "}"
        with pytest.raises(ValueError, match=kind):
            read_nk_json(text)

    def test_name_and_source_must_be_text(self):
        with pytest.raises(ValueError, match="`name` must be text, got a number"):
            read_nk_json('{"wavelength_nm": [400, 500], "n": [1, 2], "k": [0, 0], "name": 5}')
        with pytest.raises(ValueError, match="`source` must be at most 2000 characters"):
            read_nk_json(json.dumps({"wavelength_nm": [400, 500], "n": [1, 2], "k": [0, 0], "source": "s" * 3000}))

    def test_top_level_not_an_object(self):
        with pytest.raises(ValueError, match="got a list"):
            read_nk_json("[1, 2]")

    def test_too_many_samples(self):
        values = "[" + ",".join(["1"] * (MAX_SAMPLES + 1)) + "]"
        with pytest.raises(ValueError, match=f"at most {MAX_SAMPLES} numbers"):
            read_nk_json(f'{{"wavelength_nm": {values}, "n": [1], "k": [1]}}')


class TestReadNkCsvHostile:
    def test_bad_header_is_excerpted(self):
        with pytest.raises(ValueError, match="CSV header") as error:
            read_nk_csv("w" * 900 + ",n,k\n1,2,3\n")
        assert len(str(error.value)) < 200

    def test_bad_row_is_excerpted(self):
        with pytest.raises(ValueError, match="line 2 must hold three numbers") as error:
            read_nk_csv("wavelength_nm,n,k\n" + "x" * 900 + ",1,1\n")
        assert len(str(error.value)) < 200

    def test_nan_rows_are_refused(self):
        with pytest.raises(ValueError, match="finite"):
            read_nk_csv("wavelength_nm,n,k\n400,nan,1\n500,1,1\n")


class TestReadNk:
    def test_bom_and_encoding(self):
        nk = read_nk(b"\xef\xbb\xbfwavelength_nm,n,k\n400,1,1\n500,1,1\n", "csv")
        assert nk.wavelength_nm.size == 2
        with pytest.raises(ValueError, match="UTF-8"):
            read_nk(b"wavelength_nm,n,k\n\xff\xfe,1,1\n", "csv")

    @pytest.mark.parametrize("encoding", ["utf-16", "utf-16-le", "utf-16-be", "utf-32"])
    def test_utf16_and_utf32_are_named(self, encoding):
        text = "wavelength_nm,n,k\n400,1,1\n500,1,1\n".encode(encoding)
        with pytest.raises(ValueError, match="must be UTF-8 text"):
            read_nk(text, "csv")

    def test_oversized_file(self):
        with pytest.raises(ValueError, match="must be at most"):
            read_nk(b"1" * 5_000_000, "csv")

    def test_format_is_excerpted(self):
        with pytest.raises(ValueError, match="`format` must be one of") as error:
            read_nk(b"x", "q" * 500)
        assert len(str(error.value)) < 150
