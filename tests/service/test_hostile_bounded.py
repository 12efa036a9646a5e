"""
Hostile input as a fresh corpus against a real ``python -m service`` on
127.0.0.1: worst-case curve refits (degenerate bases, edits the model cannot
follow), generated with a fixed seed, ten at once on two workers. Every one
is answered 2xx, in [0, 1] (a best effort when flagged), none fits for 30 s,
the last within 1.5x the ten fits' own time over the two workers (no wait
past the work ahead of it), and a library fit sent meanwhile is answered
within 2 s: parts take turns in the workers cheapest first
(service/runtime/turns.py).
"""

from __future__ import annotations

import random
import threading
import time

import loopback
import numpy as np
import pytest

from conftest import server_process
from fitting.optics.library import LIBRARY_NAMES

pytestmark = [pytest.mark.slow, pytest.mark.server]
API = "/api/v1"
SEED = 20261221


def degenerate_base(rng: random.Random) -> dict:
    """A base with (almost) no conductor: n near 1 or a plain dielectric, k 0."""
    shape = rng.choice(["void", "dielectric", "two points"])
    if shape == "void":
        return {"nk": {"wavelength_nm": [300, 900], "n": [1.0, 1.0 + rng.random() * 1e-3], "k": [0, 0]}}
    if shape == "dielectric":
        n = rng.uniform(1.2, 2.5)
        return {"nk": {"wavelength_nm": [300, 600, 900], "n": [n, n, n], "k": [0, 0, 0]}}
    return {"nk": {"wavelength_nm": [350, 850], "n": [rng.uniform(0.1, 3), rng.uniform(0.1, 3)], "k": [0, 1e-6]}}


def unreachable_curve(rng: random.Random, base_is_metal: bool) -> dict:
    samples = rng.choice([8, 16, 31])
    angles = np.linspace(0.0, 90.0, samples)
    rgb = np.full((samples, 3), rng.uniform(0.3, 0.9))
    channel, at = rng.randrange(3), rng.uniform(30.0, 80.0)
    pull = np.exp(-0.5 * ((angles - at) / 8.0) ** 2)
    rgb[:, channel] += (rng.choice([0.0, 0.02, 1.0]) - rgb[:, channel]) * pull
    if not base_is_metal and rng.random() < 0.5:
        rgb[:] = rng.uniform(0.2, 0.8)  # a flat curve on a base with no conductor
    return {
        "eta_i": rng.choice([1.0, 1.33, 1.5, 2.0, 2.5]),
        "angle_deg": angles.tolist(),
        "rgb": np.clip(rgb, 0.0, 1.0).tolist(),
    }


def corpus(seed: int = SEED, count: int = 10) -> list[dict]:
    rng = random.Random(seed)
    out = []
    for i in range(count):
        metal = i % 2 == 1
        base = {"material": rng.choice(["Au", "Cu", "Ag", "Al", "Cr"])} if metal else degenerate_base(rng)
        curves = [unreachable_curve(rng, metal) for _ in range(rng.choice([1, 1, 2]))]
        if len({c["eta_i"] for c in curves}) < len(curves):
            curves = curves[:1]
        out.append({"name": f"worst {i}", "base": base, "curves": curves})
    return out


def test_worst_case_refits_are_bounded_and_do_not_hold_a_library_fit(tmp_path):
    answers: list[tuple[int, float, dict]] = []
    with server_process(tmp_path / "data", COATED_FIT_WORKERS="2", COATED_FIT_QUEUE="16") as server:

        def send(body):
            with loopback.Client(base_url=server.url, timeout=120) as http:
                t0 = time.perf_counter()
                response = http.post(f"{API}/fits/from-curves", json=body)
                answers.append((response.status_code, time.perf_counter() - t0, response.json()))

        threads = [threading.Thread(target=send, args=(body,)) for body in corpus()]
        for thread in threads:
            thread.start()
        with loopback.Client(base_url=server.url, timeout=120) as http:
            deadline = time.monotonic() + 30
            while http.get("/healthz").json()["fits_in_flight"] < 6 and time.monotonic() < deadline:
                time.sleep(0.02)
            t0 = time.perf_counter()
            library = http.post(f"{API}/fits", json={"material": "Ag", "eta_i_range": [1.0, 2.4]})
            library_s = time.perf_counter() - t0
        for thread in threads:
            thread.join(120)
    assert library.status_code == 201, library.text[:300]
    assert library_s < 2.0, library_s
    assert len(answers) == 10
    for status, seconds, body in answers:
        assert status in (200, 201), (status, str(body)[:300])
        target = body["metrics"]["details"]["target"]
        assert target["model_min"] >= -1e-4 and target["model_max"] <= 1.0 + 1e-4, target
        # Bounded: no worst-case refit runs 30 s (its own fit, in its worker).
        assert body["timings"]["total"] < 30.0, body["timings"]
    # And none waits past the work ahead of it: the last answer comes within 1.5x the ten fits'
    # own time shared by the two workers (idle: 18.4 s for 34.1 s of fits, 1.08x). Both sides
    # stretch alike when the machine is shared (the suite's other worker), which a fixed wall
    # bound did not: 30 s held alone (~21 s) and failed by 0.04 s in a full run.
    work = sum(body["timings"]["total"] for _, _, body in answers)
    assert max(seconds for _, seconds, _ in answers) <= 1.5 * work / 2, (sorted(a[1] for a in answers), work)


def test_a_large_scene_takes_turns_with_a_library_fit(tmp_path):
    """
    A scene is one part per material (service/jobs/scenes.py): on one worker,
    a library fit sent while a 22-material scene runs is answered before the
    scene (it takes its turn between the scene's parts), and the scene's
    report still lists every material in its order.
    """
    scene = {
        "name": "large",
        "materials": [{"material": name, "eta_i": [1.0, 1.33, 1.5, 2.0]} for name in LIBRARY_NAMES],
    }
    finished: list[tuple[str, int]] = []
    with server_process(tmp_path / "data", COATED_FIT_WORKERS="1") as server:

        def post(label: str, path: str, body: dict) -> None:
            with loopback.Client(base_url=server.url, timeout=300) as http:
                response = http.post(f"{API}{path}", json=body)
                finished.append((label, response.status_code))
                if label == "scene":
                    report = response.json()
                    assert [m["material"] for m in report["materials"]] == list(LIBRARY_NAMES)

        scene_thread = threading.Thread(target=post, args=("scene", "/scenes", scene))
        scene_thread.start()
        with loopback.Client(base_url=server.url, timeout=60) as http:
            deadline = time.monotonic() + 60
            while http.get("/healthz").json()["fits_in_flight"] < 1 and time.monotonic() < deadline:
                time.sleep(0.02)
        post("library", "/fits", {"material": "Ag", "eta_i_range": [1.0, 2.4]})
        scene_thread.join(300)
    assert finished == [("library", 201), ("scene", 200)], finished
