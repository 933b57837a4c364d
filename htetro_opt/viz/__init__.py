"""Plotting, kept apart from computing: matplotlib is imported only when a plot is drawn."""

from htetro_opt.viz.plot import SHAPE_COLOURS, plot_path, save_figure

__all__ = ["SHAPE_COLOURS", "plot_path", "save_figure"]
