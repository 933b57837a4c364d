"""Plotting, kept apart from computing: matplotlib is imported only when a plot is drawn."""

from htetro_opt.viz.animation import MAX_FPS, PathAnimation, animate_path, save_gif
from htetro_opt.viz.continuous import PLAN_COLOURS, plot_apf_potential, plot_continuous, plot_continuous_front
from htetro_opt.viz.cover import LAYER_COLOURS, plot_cover, plot_cover_heat
from htetro_opt.viz.fronts import DEFAULT_OBJECTIVES, FITNESS_OBJECTIVES, plot_convergence, plot_fronts, plot_parallel
from htetro_opt.viz.heat import HEAT_COLORMAP, plot_heat_field, plot_heat_plan
from htetro_opt.viz.plot import (
    DENSE_CELL_PT,
    SELECTION_STYLES,
    SHAPE_COLOURS,
    figure_format,
    plot_ga_plan,
    plot_path,
    save_figure,
)
from htetro_opt.viz.tiles import plot_coverage, plot_tileset

__all__ = ["SELECTION_STYLES", "SHAPE_COLOURS", "DENSE_CELL_PT", "plot_ga_plan", "plot_path", "save_figure",
           "figure_format", "plot_coverage", "plot_tileset", "animate_path", "save_gif", "PathAnimation", "MAX_FPS",
           "plot_fronts", "plot_parallel", "plot_convergence", "FITNESS_OBJECTIVES", "DEFAULT_OBJECTIVES",
           "plot_heat_field", "plot_heat_plan", "HEAT_COLORMAP", "plot_cover", "plot_cover_heat", "LAYER_COLOURS",
           "plot_continuous", "plot_apf_potential", "plot_continuous_front", "PLAN_COLOURS"]
