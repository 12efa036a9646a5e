"""
Fair shares in the fitting pool, without processes: :class:`service.runtime.shares.Shares`
(bulk slots per client and in all, worker time charged per client and
kind, the order of waiting parts) and :class:`service.runtime.turns.Turns` with
ranks (saves before every bulk part, one general turn of two or more kept
for saves). The whole, against a real server: tests/service/test_fair_shares.py.
"""

from __future__ import annotations

import asyncio

import pytest

from service.runtime.shares import Claim, ShareExceeded, Shares
from service.runtime.turns import Turns

SAVE, READ = (0, 0.0), (1, 0.0)


class TestShares:
    def test_bulk_jobs_within_their_client_s_share_and_the_bulk_share(self):
        shares = Shares(max_in_flight=5, reserved=2, per_client=2)
        a, b, c = Claim("10.0.0.1", "read"), Claim("10.0.0.2", "scene"), Claim("token", "pack")
        shares.admit(a, 1)
        shares.admit(a, 1)
        with pytest.raises(ShareExceeded, match="2 read jobs in flight, its share") as refused:
            shares.admit(a, 7)
        assert refused.value.retry_after == 7
        shares.admit(b, 1)
        with pytest.raises(ShareExceeded, match="kept for saves"):
            shares.admit(c, 1)  # three bulk jobs: the bulk share of 5 - 2
        for _ in range(10):
            shares.admit(Claim("token", "save"), 1)  # saves take no bulk slot
        shares.leave(a)
        shares.admit(c, 1)
        assert shares.bulk_in_flight() == 3

    def test_a_client_s_bulk_jobs_are_admitted_by_their_estimated_cost(self):
        shares = Shares(max_in_flight=10, reserved=2, per_client=4, client_cost_s=240.0)
        a, b = Claim("10.0.0.1", "scene"), Claim("10.0.0.2", "read")
        shares.admit(a, 1, 2048 * 0.03)  # a 64 x 32 scene: 61 s, not one job
        shares.admit(a, 1, 2048 * 0.03)
        shares.admit(a, 1, 2048 * 0.03)
        with pytest.raises(
            ShareExceeded,
            match=r"estimated at 184\.3 s of fitting; with this scene job's 61\.4 s "
            r"they would pass its share, 240 s",
        ):
            shares.admit(a, 1, 2048 * 0.03)
        shares.admit(a, 1, 1.0)  # a small read still fits
        shares.admit(b, 1, 500.0)  # another client's first job is admitted by cost whatever it is
        shares.leave(a, 2048 * 0.03)
        shares.leave(a, 1.0)
        shares.admit(a, 1, 2048 * 0.03)  # the cost given back
        assert shares.bulk_in_flight() == 4

    def test_charged_time_orders_bulk_clients_and_decays(self, monkeypatch):
        import service.runtime.shares as module

        now = [1000.0]
        monkeypatch.setattr(module.time, "monotonic", lambda: now[0])
        shares = Shares(max_in_flight=4, reserved=1, per_client=1)
        heavy, light = Claim("10.0.0.1", "read"), Claim("10.0.0.2", "scene")
        shares.charge(heavy, 30.0)
        shares.charge(light, 1.0)
        assert shares.rank(light) < shares.rank(heavy)
        assert shares.rank(Claim("10.0.0.1", "save")) == (0, 0.0) < shares.rank(light)
        now[0] += module.HALF_LIFE_S
        assert shares.standing("10.0.0.1") == pytest.approx(15.0)
        assert shares.charged_by_kind["read"] == 30.0 and shares.charged_by_kind["scene"] == 1.0

    def test_bad_shares_refused(self):
        with pytest.raises(ValueError, match="`reserved`"):
            Shares(max_in_flight=2, reserved=2, per_client=1)
        with pytest.raises(ValueError, match="`per_client`"):
            Shares(max_in_flight=2, reserved=1, per_client=0)


def test_a_save_goes_before_every_bulk_part_and_has_a_turn_kept():
    async def body():
        turns, started = Turns(2), []
        gates: dict[str, asyncio.Event] = {}

        async def part(name, rank, cost=1.0):
            gates[name] = asyncio.Event()
            async with turns.turn(cost, rank):
                started.append(name)
                await gates[name].wait()

        bulk = [asyncio.ensure_future(part(f"read{i}", READ, 0.01 * i)) for i in range(3)]
        await asyncio.sleep(0)
        assert started == ["read0"] and turns.bulk_running == 1  # bulk parts hold one general turn of two
        save = asyncio.ensure_future(part("save", SAVE, 5.0))  # dearer, yet first: a turn is kept for it
        await asyncio.sleep(0)
        assert started == ["read0", "save"]
        gates["read0"].set()
        await bulk[0]
        await asyncio.sleep(0)
        assert started == ["read0", "save", "read1"]
        later = asyncio.ensure_future(part("save2", SAVE, 5.0))  # waits, then goes before read2
        await asyncio.sleep(0)
        gates["save"].set()
        await save
        await asyncio.sleep(0)
        assert started[-1] == "save2"
        for name in ("read1", "save2"):
            gates[name].set()
        await asyncio.sleep(0.01)
        gates["read2"].set()
        await asyncio.gather(*bulk, later)
        return started, turns.running, turns.bulk_running

    started, running, bulk_running = asyncio.run(body())
    assert started == ["read0", "save", "read1", "save2", "read2"] and running == bulk_running == 0


def test_one_worker_is_shared_and_bulk_parts_never_take_express_turns():
    async def body():
        turns, started = Turns(1, express=1, express_cost_s=0.1), []
        gate = asyncio.Event()

        async def part(name, rank, cost):
            async with turns.turn(cost, rank):
                started.append(name)
                await gate.wait()

        tasks = [
            asyncio.ensure_future(part("read", READ, 1.0)),
            asyncio.ensure_future(part("cheap read", READ, 0.01)),
            asyncio.ensure_future(part("live step", SAVE, 0.03)),
        ]
        await asyncio.sleep(0)
        assert started == ["read", "live step"]  # one worker: bulk may use it; the express turn is a save's
        gate.set()
        await asyncio.gather(*tasks)
        return started

    assert asyncio.run(body()) == ["read", "live step", "cheap read"]


def test_save_rate_per_client_per_minute(monkeypatch):
    import service.runtime.shares as module
    from service.runtime.shares import SaveRate, TooManySaves

    now = [500.0]
    monkeypatch.setattr(module.time, "monotonic", lambda: now[0])
    rate, a, b = SaveRate(2), Claim("10.0.0.1", "save"), Claim("token", "save")
    rate.note(a)
    now[0] += 20.0
    rate.note(a)
    with pytest.raises(TooManySaves, match="saved 2 times in the last minute") as refused:
        rate.note(a)
    assert refused.value.retry_after == 40
    rate.note(b)  # another client keeps its own
    now[0] += 40.0
    rate.note(a)  # the first save has left the window


@pytest.mark.slow  # starts the fitting pool's processes
def test_saves_past_the_rate_are_429_with_retry_after(tmp_path):
    from conftest import app_client

    with app_client(tmp_path, saves_per_client_per_minute=2, metrics_samples=10) as client:
        # Repeats of the latest version add nothing: neither counted nor refused; Cu is the second save.
        answers = [client.post("/api/v1/fits", json={"material": m}) for m in ("Au",) * 4 + ("Cu", "Ag")]
        draft = client.post(
            "/api/v1/fits/from-curves",
            json={
                "draft": True,
                "base": {"material": "Au"},
                "curves": [
                    {
                        "eta_i": 1.5,
                        "angle_deg": [0, 30, 60, 75, 90],
                        "rgb": [[0.9, 0.7, 0.35], [0.9, 0.7, 0.35], [0.88, 0.69, 0.36], [0.85, 0.7, 0.45], [1, 1, 1]],
                    }
                ],
            },
        )
    assert [a.status_code for a in answers] == [201, 200, 200, 200, 201, 429], answers[-1].text
    assert "COATED_SAVES_PER_CLIENT_PER_MINUTE" in answers[-1].json()["detail"]
    assert int(answers[-1].headers["retry-after"]) >= 1
    assert draft.status_code == 201, draft.text  # a draft is not a save: never counted
