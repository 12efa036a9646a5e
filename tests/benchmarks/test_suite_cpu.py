"""
benchmarks/suite_cpu.py: the class of a process by its command line, and
the sampler's count of a process's CPU time (a child that spins about a
second of CPU is seen, in its class, with that time).
"""

from __future__ import annotations

import subprocess
import sys

import pytest

from benchmarks.suite_cpu import LABELS, Sampler, classify
from benchmarks.suite_time import TICK, calibration

CHROMIUM = "/usr/lib/chromium/chromium --headless --no-sandbox"


@pytest.mark.parametrize(
    "command, key",
    [
        (f"{CHROMIUM} --type=renderer --enable-automation", "chromium_renderer"),
        (f"{CHROMIUM} --type=gpu-process --use-angle=swiftshader", "chromium_gpu"),
        (f"{CHROMIUM} --type=zygote", "chromium_other"),
        (f"{CHROMIUM} --remote-debugging-pipe", "chromium_browser"),
        (
            "/r/.venv/bin/python -B -c from multiprocessing.forkserver import main; main(18, 19, ['service.runtime.preload'])",
            "fork_servers",
        ),
        ("/r/.venv/bin/python -m service --host 127.0.0.1 --port 40123 --data-dir /tmp/x", "servers"),
        (".venv/bin/python -m pytest -n 2 --dist loadscope", "pytest"),
        ("/r/.venv/bin/python -u -c import sys;exec(eval(sys.stdin.readline()))", "pytest"),
        ("/r/.venv/lib/python3.11/site-packages/playwright/driver/node run-driver", "playwright"),
        ("node node_modules/gltf-validator/cli.js a.gltf", "node"),
        ("/usr/lib/postgresql/15/bin/postgres -D /tmp/coated-pg-1", "postgres"),
        ("/r/.venv/bin/python -m fitting fit Au --eta-i 1.5", "cli"),
        ("/r/.venv/bin/python -c print(1)", "other_python"),
        ("/usr/bin/glslangValidator shader.frag", "other"),
        ("", "kernel"),
    ],
)
def test_a_process_is_classed_by_its_command_line(command, key):
    assert classify(command) == key
    assert key in LABELS


def test_a_server_s_forks_are_fork_servers():
    server = "/r/.venv/bin/python -m service --host 127.0.0.1 --port 40123 --data-dir /tmp/x"
    assert classify(server, "pytest") == "servers"
    assert (
        classify(server, "servers") == "fork_servers"
    )  # its fork server (service.runtime.fork_server.start_fork_server)
    assert classify(server, "fork_servers") == "fork_servers"  # that fork server's workers
    assert classify(".venv/bin/python -m pytest", "servers") == "pytest"


def test_a_server_forked_by_the_tests_program_is_a_server():
    program = "/r/.venv/bin/python -c import runpy; runpy.run_path('tests/server_forks.py', run_name='__main__')"
    assert classify(program, "pytest") == "servers"  # the program: its imports are the servers' start
    assert classify(program, "servers", leader=True) == "servers"  # a server it forked (its own session)
    assert classify(program, "servers") == "fork_servers"  # that server's fork server
    assert classify(program, "fork_servers") == "fork_servers"  # and its workers


def test_the_calibration_loop_takes_cpu_time():
    assert 0.0 < calibration(rounds=1) < 60.0  # the record takes the best of 3 of the same loop


@pytest.mark.slow
def test_the_sampler_counts_a_child_s_cpu_time_in_its_class():
    sampler = Sampler(0.05)
    sampler.start()
    spin = "import time\nstart = time.process_time()\nwhile time.process_time() - start < 1.0: pass\n"
    child = subprocess.Popen([sys.executable, "-c", spin])
    assert child.wait(timeout=60) == 0
    sampler.done.set()
    sampler.join()
    mine = [
        (label, (last - first) / TICK)
        for (pid, _), (label, first, last, _) in sampler.seen.items()
        if pid == str(child.pid)
    ]
    assert [label for label, _ in mine] == ["other_python"], mine
    # Its whole CPU time but what it spent after the last sample (under one interval), and its start-up.
    assert 0.9 <= mine[0][1] <= 1.5, mine
