import os
import signal

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
