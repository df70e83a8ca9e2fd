import os

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
