r"""Statistics on the unit sphere for any unit-vector series (tilt, heading, posture).

Submodules
----------
* :mod:`~tiltlab.sphere.mesh` — Fibonacci lattice, its spherical Delaunay triangulation,
  exact facet areas, vectorised point location, tilt maps and visited fractions
  (Fayat et al. 2021, §2.7);
* :mod:`~tiltlab.sphere.vmf` — von Mises–Fisher maximum likelihood (weighted, exact κ),
  density, sampling and bootstrap confidence cones;
* :mod:`~tiltlab.sphere.tiltpoint` — the mean tilt point of a map and its angle to the
  sagittal plane (Fayat et al. §2.8, §3.3), rotation of a baseline to the pole
  (Fig. 3e);
* :mod:`~tiltlab.sphere.kde` — equal-area grids, location- and movement-based vMF kernel
  density estimation (mass-conserving on the grid by default: it integrates to 1 for
  any bandwidth, even at the grid's poles), reference bandwidth, cumulative isopleths,
  stationarity check (Benhamou 2023, §7);
* :mod:`~tiltlab.sphere.residence` — residence time and number of visits
  (Benhamou 2023, App. C);
* :mod:`~tiltlab.sphere.brb` — movement-based KDE with biased random bridges, weighted by
  time, residence or visits, and residence maps on a KDE grid (Benhamou 2023, §7);
* :mod:`~tiltlab.sphere.turns` — kernel densities of changes of heading (arc direction
  and size on the sphere, direction on the circle);
* :mod:`~tiltlab.sphere.text` — directions as printed text.

Everything is re-exported here: ``from tiltlab import sphere; sphere.tilt_map(g)``.

Every function that takes a series of directions accepts a labelled (time, axis)
DataArray — e.g. ``filters.gravity(filters.estimate(rec, method))``, whose ``fs`` and
``time`` coordinate are used where durations are needed (``tilt_map``'s ``time``,
``mkde``, ``residence*``, ``passage_times``) — a Recording with a ``gravity`` variable,
or a plain (N, 3) array with ``fs=``/``times=``.

Map figures (3-D sphere, Lambert azimuthal equal-area with cartopy, heat maps, KDE
maps) are in :mod:`tiltlab.plot` (:mod:`tiltlab.plot.maps`, :mod:`tiltlab.plot.mapfigures`).
"""

from .mesh import (
    EDGE_EPS,
    SphereMesh,
    as_unit_vectors,
    fibonacci_lattice,
    from_lonlat,
    histogram,
    locate,
    sphere_mesh,
    spherical_triangle_area,
    tilt_map,
    to_lonlat,
    triangulate,
    visited,
    visited_fraction,
)
from .vmf import (
    ConfidenceCone,
    VMFFit,
    a3,
    a3_inverse,
    angle,
    vmf_bootstrap,
    vmf_cap_area,
    vmf_fit,
    vmf_logpdf,
    vmf_pdf,
    vmf_sample,
)
from .kde import (
    EqualAreaGrid,
    SphericalKDE,
    equal_area_grid,
    grid_for,
    isopleth_mask,
    isopleths,
    kde,
    mkde,
    reference_bandwidth,
    slerp,
    slerp_vectors,
    stationarity_thirds,
)
from .brb import (
    ResidenceMap,
    brb,
    brb_diffusion,
    bridge_bandwidth,
    kde_distance,
    residence_map,
)
from .turns import circular_kde, heading_change_kde, heading_change_vectors
from .tiltpoint import (
    mean_tilt_point,
    rotate_to_pole,
    rotation_to_pole,
    sagittal_angle,
)
from .residence import Residence, passage_times, residence, residence_series
from .text import format_direction

__all__ = [
    "EDGE_EPS",
    "SphereMesh",
    "as_unit_vectors",
    "fibonacci_lattice",
    "from_lonlat",
    "histogram",
    "locate",
    "sphere_mesh",
    "spherical_triangle_area",
    "tilt_map",
    "to_lonlat",
    "triangulate",
    "visited",
    "visited_fraction",
    "ConfidenceCone",
    "VMFFit",
    "a3",
    "a3_inverse",
    "angle",
    "mean_tilt_point",
    "rotate_to_pole",
    "rotation_to_pole",
    "sagittal_angle",
    "vmf_bootstrap",
    "vmf_cap_area",
    "vmf_fit",
    "vmf_logpdf",
    "vmf_pdf",
    "vmf_sample",
    "EqualAreaGrid",
    "SphericalKDE",
    "equal_area_grid",
    "grid_for",
    "isopleth_mask",
    "isopleths",
    "kde",
    "mkde",
    "reference_bandwidth",
    "slerp",
    "slerp_vectors",
    "stationarity_thirds",
    "Residence",
    "passage_times",
    "residence",
    "residence_series",
    "format_direction",
    "ResidenceMap",
    "brb",
    "brb_diffusion",
    "bridge_bandwidth",
    "residence_map",
    "kde_distance",
    "circular_kde",
    "heading_change_kde",
    "heading_change_vectors",
]
