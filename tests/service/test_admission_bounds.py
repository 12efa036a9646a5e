"""
:class:`service.runtime.admission.Admission` alone, with stand-in
connections: what a new connection past a bound closes, the reserve's own
bound, and when every connection counts as held.
"""

from __future__ import annotations

from dataclasses import dataclass

from service.runtime.admission import HEALTH_RESERVE, IDLE_GRACE_S, Admission


@dataclass(eq=False)
class Fake:
    host: str | None
    last_active: float = 0.0
    busy: bool = False  # a request in progress (a body at the rate, or the app at work)
    served: bool = False
    sent: bool = False  # its request has begun
    closed: bool = False

    def idle(self) -> bool:
        return not self.busy and not self.closed

    def waiting(self) -> bool:
        return not self.sent and not self.closed

    def close(self) -> None:
        self.closed = True


def _open(admission: Admission, connection: Fake, now: float) -> bool:
    connection.last_active = now
    admission.touch(connection)
    return admission.admit(connection, now)


def test_the_service_bound_closes_the_longest_idle_but_not_a_keep_alive_just_answered():
    admission = Admission(max_connections=3, max_per_client=100)
    busy, reader, fresh = Fake("10.0.0.1", busy=True), Fake("10.0.0.2", served=True), Fake("10.0.0.3")
    assert _open(admission, busy, 0.0) and _open(admission, reader, 5.0) and _open(admission, fresh, 5.1)
    # The reader's connection is the longest idle, but its next request may be on its way: the fresh one goes.
    assert _open(admission, Fake("10.0.0.4"), 5.2)
    assert fresh.closed and not reader.closed and not busy.closed
    assert _open(admission, Fake("10.0.0.5"), 5.0 + IDLE_GRACE_S + 0.1)  # past the grace it is idle like any
    assert reader.closed


def test_with_every_connection_busy_a_new_one_goes_to_the_reserve_and_the_replica_is_held():
    admission = Admission(max_connections=2, max_per_client=100)
    assert admission.held() is None
    for host in ("a", "b"):
        assert _open(admission, Fake(host, busy=True), 0.0)
    assert "COATED_MAX_CONNECTIONS" in admission.held()
    probe = Fake("prober")
    assert not _open(admission, probe, 1.0)
    assert probe in admission.reserve and probe not in admission.everyone and not probe.closed


def test_the_reserve_past_its_bound_closes_a_silent_one_of_the_address_holding_most():
    admission = Admission(max_connections=1, max_per_client=100)
    assert _open(admission, Fake("x", busy=True), 0.0)
    probe = Fake("prober")
    assert not _open(admission, probe, 0.0)
    flood = [Fake("flooder") for _ in range(HEALTH_RESERVE)]
    for c in flood:
        assert not _open(admission, c, 0.1)
    assert len(admission.reserve) == HEALTH_RESERVE
    assert not probe.closed and flood[0].closed and sum(c.closed for c in flood) == 1
