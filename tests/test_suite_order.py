"""
The order pytest-xdist hands out the suite's modules under ``--dist
loadscope`` (``scripts/test``): the collection's order, which
``tests/conftest.py`` sorts (browser modules first, then server ones, then
the rest), and not pytest-xdist's default, which sorts the scopes by their
number of tests (pyproject.toml's ``--no-loadscope-reorder``). Sorted by
size, the browser modules (2 to 10 tests each) went last and apart: the
longest modules ran at the end of the run, and the shared Chromium, which
closes after the last of a run of browser tests, was launched again for
most browser modules.
"""

from __future__ import annotations

from types import SimpleNamespace

from xdist.scheduler import LoadScopeScheduling

COLLECTION = [
    "tests/static/test_editor_a.py::test_one",
    "tests/static/test_editor_a.py::test_two",
    "tests/service/test_server_b.py::test_one",
    *(f"tests/fitting/test_many.py::test_{i}" for i in range(9)),
    "tests/fitting/test_class.py::TestOne::test_a",
    "tests/fitting/test_class.py::TestOne::test_b",
    "tests/fitting/test_class.py::TestTwo::test_a",
    *(f"tests/fitting/test_more.py::test_{i}" for i in range(5)),
]


class Worker:
    """What the scheduler calls on a worker; each unit of work it sends goes on ``sent`` (shared)."""

    def __init__(self, name: str, sent: list[list[int]]) -> None:
        self.gateway = SimpleNamespace(id=name)
        self.sent = sent
        self.shutting_down = False

    def send_runtest_some(self, indices) -> None:
        self.sent.append(list(indices))

    def shutdown(self) -> None:
        pass


def two_workers(pytestconfig, **options) -> SimpleNamespace:
    """This run's options as ``-n 2`` sets them (two local workers), with ``options`` over them."""
    option = SimpleNamespace(**{**vars(pytestconfig.option), "tx": ["2*popen"], **options})
    return SimpleNamespace(option=option, getvalue=lambda name: getattr(option, name))


def handed_out(config) -> list[str]:
    """The scopes pytest-xdist's scheduler hands two workers, in the order it hands them out."""
    scheduler, sent = LoadScopeScheduling(config), []
    for worker in (Worker("gw0", sent), Worker("gw1", sent)):
        scheduler.add_node(worker)
        scheduler.add_node_collection(worker, COLLECTION)
    scheduler.schedule()
    # Its first units (two a worker, in turn), then those still in its queue, in the order it pops them.
    return [*(scheduler._split_scope(COLLECTION[unit[0]]) for unit in sent), *scheduler.workqueue]


def test_the_suite_keeps_its_own_order(pytestconfig):
    assert pytestconfig.option.loadscopereorder is False
    assert handed_out(two_workers(pytestconfig)) == [
        "tests/static/test_editor_a.py",
        "tests/service/test_server_b.py",
        "tests/fitting/test_many.py",
        "tests/fitting/test_class.py::TestOne",
        "tests/fitting/test_class.py::TestTwo",
        "tests/fitting/test_more.py",
    ]


def test_xdist_default_would_sort_by_size(pytestconfig):
    """The check above can fail: with pytest-xdist's default the largest scope goes first."""
    assert handed_out(two_workers(pytestconfig, loadscopereorder=True))[0] == "tests/fitting/test_many.py"
