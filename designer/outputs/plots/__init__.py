"""Plots of a finished design and of the search's trade-offs (PNG and SVG).

The charts follow the source paper (Noh et al. 2025): the operating region bounded by the
moment isolines (its Fig. 3, ``region``), the bridges' voltage isolines (Fig. 2, ``isolines``)
and the predicted error maps over the operating region (Figs. 16-17, ``error_maps``), plus the
ranking of every material and section family the search tried (``candidates``) and the fronts
of accuracy against stiffness and speed (``tradeoff``); ``write`` writes them all as files.

Each module first computes, from a design.json dictionary read into ``sensor.SensorData``, the
numbers behind its plot (``operating_region``, ``error_map``, ``bridge_map``) as plain frozen
dataclasses and arrays, SI throughout; the error maps use ``designer.model.estimator`` so that
what is drawn is what the estimator predicts. It then draws them: every ``plot_*`` function
takes the data and ``ax=None`` (or ``fig=None``), returns the matplotlib Figure, never calls
``pyplot`` and never touches the global rcParams. matplotlib is imported only inside the
drawing functions. Axes carry engineering units (N, mm, mV, %, Hz); ``common`` holds the
colours, formats and axes every plot shares.
"""

from designer.outputs.plots.candidates import plot_candidates, rank_candidates
from designer.outputs.plots.common import ERROR_OBJECTIVE_LABEL
from designer.outputs.plots.error_maps import ErrorMap, error_map, plot_error_maps, worst_errors
from designer.outputs.plots.isolines import bridge_map, example_load, plot_voltage_isolines
from designer.outputs.plots.region import MomentLimit, OperatingRegion, operating_region, plot_operating_region
from designer.outputs.plots.sensor import SensorData
from designer.outputs.plots.tradeoff import TRADEOFF_AXES, TRADEOFF_GROUPS, plot_tradeoff
from designer.outputs.plots.write import FORMATS, PLOT_NAMES, PNG_DPI, write_design_plots

__all__ = ["ERROR_OBJECTIVE_LABEL", "FORMATS", "PLOT_NAMES", "PNG_DPI", "TRADEOFF_AXES", "TRADEOFF_GROUPS", "ErrorMap",
           "MomentLimit", "OperatingRegion", "SensorData", "bridge_map", "error_map", "example_load",
           "operating_region", "plot_candidates", "plot_error_maps", "plot_operating_region", "plot_tradeoff",
           "plot_voltage_isolines", "rank_candidates", "worst_errors", "write_design_plots"]
