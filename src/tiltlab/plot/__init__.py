"""Figure recipes shared by the book's chapters (layer 8; matplotlib, cartopy for maps).

No computation here beyond what a figure needs. Every recipe takes its data first —
labelled where possible, so that axis labels carry the data's units and times come from
the ``time`` coordinate — an optional ``ax``, and returns the axes (or the figure for
multi-panel recipes). Axes are always labelled with units, several lines get a legend and
maps get a colour bar.

Submodules
----------
* :mod:`~tiltlab.plot.recording` — Recordings and named series against time, angular
  speed traces and histograms;
* :mod:`~tiltlab.plot.maps` — sphere figures: LAEA maps on a unit globe (cartopy), 3-D
  facet renderings, time-on-sphere heat maps, visited facets, KDE maps with isopleths,
  grids of maps, residence maps ;
* :mod:`~tiltlab.plot.scores` — estimator errors: parameter-grid heat maps and curves,
  per-trial bars, ECDFs, errors binned by speed;
* :mod:`~tiltlab.plot.cohort` — Tukey boxplots and group means for cohort tables, mean-tilt
  trajectories with each baseline at the pole (Fig. 3e);
* :mod:`~tiltlab.plot.immobility` — the angular-speed distribution split by an
  immobility mask (Fayat Fig. A3);
* :mod:`~tiltlab.plot.movement` — changes of heading and flight classes;
* :mod:`~tiltlab.plot.benchmark` — gravity trajectories side by side (Fig. 2b);
* :mod:`~tiltlab.plot.learning` — training curves and per-trial errors by method;
* :mod:`~tiltlab.plot.tables` — :func:`table`, the table recipe: headers with units,
  rounding by quantity, p-values written once.

Everything is re-exported here: ``from tiltlab import plot; plot.kde_map(k)``.
"""

from .benchmark import tilt_trajectories_panels
from .calibration import (
    calibration_log_figure,
    mag_calibration_figure,
    norm_error_band_figure,
)
from .immobility import immobility_speed_distribution
from .cohort import group_lines, tilt_trajectories_figure, tukey_boxplot
from .filters import estimates_overview, plain_log_ticks, running_rms, tilt_angle_deg
from .learning import learning_curves, method_strips
from .movement import flight_classes_figure, heading_change_figure
from .mapfigures import (
    facet_map,
    kde_map,
    map_grid,
    residence_figure,
    tilt_heatmap,
    tilt_overview,
    tilt_points_map,
    tilt_trace,
    visited_map,
)
from .maps import (
    SENSOR_AXES,
    axis_names,
    axis_texts,
    decorate,
    laea,
    lonlat_deg,
    map_axes,
    plot_facets,
    plot_grid,
    plot_isopleths,
    plot_mask,
    plot_points,
    project,
    sphere_3d,
    tilt_projection,
    unit_globe,
)
from .recording import (
    plot_recording,
    plot_vectors,
    series_panels,
    shade_mask,
    speed_histogram,
    speed_trace,
)
from .scores import binned_errors, ecdf_plot, score_curves, score_heatmap, trial_bars
from .tables import DECIMALS, MAX_HEADER, MISSING, P_DECIMALS, table

from .benchmark import __all__ as _benchmark_all
from .cohort import __all__ as _cohort_all
from .filters import __all__ as _filters_all
from .learning import __all__ as _learning_all
from .mapfigures import __all__ as _mapfigures_all
from .maps import __all__ as _maps_all
from .movement import __all__ as _movement_all
from .recording import __all__ as _recording_all
from .scores import __all__ as _scores_all
from .tables import __all__ as _tables_all

__all__ = [
    "calibration_log_figure",
    "norm_error_band_figure",
    "immobility_speed_distribution",
    *_recording_all,
    "SENSOR_AXES",
    *_maps_all,
    *_mapfigures_all,
    *_scores_all,
    *_cohort_all,
    *_learning_all,
    *_movement_all,
    *_filters_all,
    *_tables_all,
    *_benchmark_all,
]
