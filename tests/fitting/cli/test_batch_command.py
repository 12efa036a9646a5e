"""``python -m fitting batch`` (:mod:`fitting.cli.batch`)."""

from __future__ import annotations

import json

from fitting.batch import OUTPUT_FILES
from fitting.cli.main import main


class TestBatchCommand:
    def test_page_list_to_pack_and_report(self, tmp_path, capsys):
        listing = tmp_path / "pages.txt"
        listing.write_text("main/Au/Johnson\nmain/Al/Mathewson\n")
        out = tmp_path / "out"
        rc = main(["batch", "--page-list", str(listing), "-o", str(out), "--workers", "1", "--samples", "20"])
        assert rc == 0
        assert all((out / name).exists() for name in OUTPUT_FILES)
        captured = capsys.readouterr()
        summary = json.loads(captured.out)
        assert summary["fitted"] == 1 and summary["skipped"] == 1
        assert "2/2 pages" in captured.err  # the progress bar, on stderr

    def test_bad_arguments_exit_2_with_the_rule(self, tmp_path, capsys):
        assert main(["batch", "--book", "Nope", "-o", str(tmp_path)]) == 2
        assert "`book` 'Nope' is not on shelf 'main'" in capsys.readouterr().err
        assert main(["batch", "--book", "Au", "--workers", "0", "-o", str(tmp_path)]) == 2
        assert "`workers` must be an integer >= 1, got 0" in capsys.readouterr().err
