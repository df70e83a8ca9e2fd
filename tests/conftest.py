import os
import signal
from pathlib import Path

os.environ.setdefault("MPLBACKEND", "Agg")

import pytest  # noqa: E402

from drakecreep.params import preset, with_value  # noqa: E402


@pytest.fixture(scope="session")
def paper():
    """The paper preset."""
    return preset("paper")


@pytest.fixture(scope="session")
def short_paper(paper):
    """The paper preset with the metrics window starting at 0.3 s, for short runs."""
    return with_value(paper, "simulation.steady_start", 0.3)


@pytest.fixture
def ctrl_c_as_at_a_terminal():
    """SIGINT raises KeyboardInterrupt, as at a terminal, for the duration of a test.

    A shell starts a background job (``cmd &`` without job control, ``nohup``) with SIGINT ignored, and Python
    then keeps it ignored: a suite run so would see a test's Ctrl-C do nothing."""
    before = signal.signal(signal.SIGINT, signal.default_int_handler)
    yield
    signal.signal(signal.SIGINT, before)


#: the test files that take longest (10-330 s each on one of two cores, session 77's ``--durations=0``), longest
#: first: with ``--dist loadfile`` a worker takes whole files in the order collected, and a long file collected in
#: the middle of the suite (test_drive_fit.py, a quarter of all the test time) left the other worker idle at the
#: end; the files of 10-30 s are listed too, so that the last files handed out are the short ones
LONGEST_FIRST = ("gap/test_drive_fit.py", "gap/test_benchmark.py", "gap/test_drake_diagnosis.py",
                 "studies/test_compensation.py", "gap/test_screen.py", "test_analysis_scripts.py", "gap/test_truth.py",
                 "gap/test_drake_replay_drakecreep.py", "report/test_loop_report.py", "servo/test_tuning.py",
                 "gap/test_drake_replay.py", "cli/test_diagnose_drakecreep.py", "sim/test_baseline.py",
                 "sim/test_sweep.py", "cli/test_gap_benchmark.py", "cli/test_reproduce_compensate.py", "test_docs.py",
                 "cli/test_bad_input.py", "studies/test_paper_reproduction.py", "model/test_axis.py",
                 "servo/test_loops.py", "sim/test_simulation.py", "cli/test_cli_options.py", "cli/test_diagnose.py",
                 "model/test_nut_friction.py")


def pytest_collection_modifyitems(config, items):
    """Collect :data:`LONGEST_FIRST` first, longest first; every other file after them in its own order (a stable
    sort: each file's tests stay together and in order, so its module fixtures are still built once)."""
    root = Path(__file__).parent

    def rank(item):
        try:
            name = Path(item.path).relative_to(root).as_posix()
        except ValueError:
            return len(LONGEST_FIRST)
        return LONGEST_FIRST.index(name) if name in LONGEST_FIRST else len(LONGEST_FIRST)

    items.sort(key=rank)
