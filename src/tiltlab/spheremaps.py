"""Sphere figures — moved to :mod:`tiltlab.plot.maps`; this module re-exports them.

``from tiltlab import spheremaps as SM`` keeps working (``SM.map_axes``, ``SM.plot_facets``,
``SM.decorate``...); new code should use ``from tiltlab import plot`` (``plot.map_axes``,
``plot.kde_map``...). ``spheremaps.offline()`` was removed: the maps never request
network data (no Natural Earth features on a unit globe), so there is nothing to guard.
"""

from .plot.maps import *  # noqa: F401,F403
from .plot.maps import SENSOR_AXES, __all__  # noqa: F401
