"""Plots are drawn off-screen, and every figure a test opens is closed after it."""

import matplotlib
import pytest

matplotlib.use("Agg")  # before pyplot is first imported (htetro_opt.viz imports it lazily)


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    import matplotlib.pyplot as plt

    plt.close("all")
