"""
service.store.shared_check.SharedCheck: one run of the check at a time;
callers that come during it take its outcome (its errors as copies of
their own), a follower's wait is bounded, and the next call after a run
runs it again.
"""

from __future__ import annotations

import threading
import time

import pytest
from at_once import at_once

from service.store.shared_check import SharedCheck


class Refused(Exception):
    pass


def slow(runs, outcome=None, seconds=0.5):
    def check():
        runs.append(threading.get_ident())
        time.sleep(seconds)
        if outcome is not None:
            raise outcome

    return check


def test_callers_during_a_run_share_it():
    runs = []
    shared = SharedCheck(slow(runs), Refused, wait_s=10)
    assert at_once(shared) == [None] * 8
    assert len(runs) == 1


def test_a_refusal_reaches_every_caller_as_its_own_copy():
    runs = []
    shared = SharedCheck(slow(runs, Refused("connection refused")), Refused, wait_s=10)
    outcomes = at_once(shared)
    assert len(runs) == 1
    assert all(type(e) is Refused and str(e) == "connection refused" for e in outcomes), outcomes
    assert len({id(e) for e in outcomes}) == len(outcomes)  # no object raised in two threads


def test_the_next_call_after_a_run_runs_it_again():
    runs = []
    shared = SharedCheck(slow(runs, seconds=0.0), Refused, wait_s=10)
    shared()
    shared()
    assert len(runs) == 2


def test_a_follower_waits_at_most_wait_s():
    runs, started, release = [], threading.Event(), threading.Event()

    def check():
        runs.append(1)
        started.set()
        release.wait(10)  # the leader's check runs until the follower has given up

    shared = SharedCheck(check, Refused, wait_s=0.1)
    leader = threading.Thread(target=shared)
    leader.start()
    started.wait(10)
    begun = time.monotonic()
    try:
        with pytest.raises(Refused, match="no outcome of another call's check within 0.1 s"):
            shared()
        assert time.monotonic() - begun < 0.9
        assert leader.is_alive()  # refused while the check it would have shared still ran
    finally:
        release.set()
        leader.join()
    assert len(runs) == 1


def test_another_exception_reaches_its_caller_and_followers_are_refused():
    runs = []
    shared = SharedCheck(slow(runs, KeyError("bug")), Refused, wait_s=10)
    outcomes = at_once(shared, n=4)
    assert len(runs) == 1
    assert sum(isinstance(e, KeyError) for e in outcomes) == 1
    assert sum(isinstance(e, Refused) and "did not finish" in str(e) for e in outcomes) == 3, outcomes
