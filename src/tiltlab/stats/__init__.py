r"""Group statistics of cohort features (layer 7).

Rank tests between groups and against baseline, multiple-comparison adjustments (including Fayat et al.'s uncapped
Bonferroni convention), effect sizes with confidence intervals, a longitudinal mixed
model, and power by simulation.

One implementation each:

* :mod:`~tiltlab.stats.nonparametric` — :func:`mann_whitney`,
  :func:`wilcoxon_signed_rank` (exact, exact conditional with ties/zeros, or
  asymptotic, the method recorded), the exact p-value lattices;
* :mod:`~tiltlab.stats.multiple` — :func:`adjust`, :func:`paper_bonferroni`,
  :data:`FAYAT_FAMILIES` (18 between groups, 6 against baseline);
* :mod:`~tiltlab.stats.effects` — rank-biserial correlation, probability of
  superiority, Hodges–Lehmann shift with its exact distribution-free interval;
* :mod:`~tiltlab.stats.mixed` — :func:`mixed_model` (MixedLM with convergence checks);
* :mod:`~tiltlab.stats.permutation` — :func:`permutation_interaction`, the group × time
  interaction tested by relabelling whole subjects (exact or random relabellings);
* :mod:`~tiltlab.stats.power` — :func:`power_by_simulation`, :func:`animals_needed`
  for a user-supplied simulator (this package never imports :mod:`tiltlab.simulate`);
* :mod:`~tiltlab.stats.design` — :func:`study_design`: groups, control, time points,
  baseline, test directions and families read from a cohort table (:class:`StudyDesign`);
* :mod:`~tiltlab.stats.cells` — :func:`long_table`, :func:`check_cells`: the sessions
  of each group × time point of a cohort table, one animal per cell;
* :mod:`~tiltlab.stats.tables` — :func:`between_groups`, :func:`against_baseline`
  (tidy tables from a cohort Dataset/DataFrame, with the Bonferroni family stated) and
  :func:`format_table` (Tables A1–A8 layout);
* :mod:`~tiltlab.stats.summaries` — :func:`group_quantiles`, :func:`significant_cells`,
  :func:`with_published` (our p-values next to the printed Tables A1–A2) and
  :func:`recovery_table` (planted versus estimated differences of a simulated cohort).

Example
-------
>>> import tiltlab.stats as S
>>> float(6 * S.signed_rank_p_lattice(5)['p'].iloc[0])  # Fayat Table A2: 0.188
0.1875
"""

from .cells import check_cells, long_table
from .design import StudyDesign, design_tables, session_table, study_design
from .effects import (
    Interval,
    hodges_lehmann,
    paired_prob_superiority,
    paired_rank_biserial,
    prob_superiority,
    rank_biserial,
)
from .mixed import MixedModelResult, mixed_model
from .multiple import (
    ADJUSTMENTS,
    FAYAT_FAMILIES,
    add_adjustments,
    adjust,
    family_caption,
    paper_bonferroni,
)
from .nonparametric import (
    ALTERNATIVES,
    EXACT_MAX_CELLS,
    EXACT_MAX_PAIRS,
    ZERO_METHODS,
    TestResult,
    exact_p_lattice,
    mann_whitney,
    mwu_null_distribution,
    signed_rank_null_distribution,
    signed_rank_p_lattice,
    wilcoxon_signed_rank,
)
from .permutation import permutation_interaction
from .published import (
    FAYAT_DESIGN,
    FAYAT_FEATURE_TABLES,
    FAYAT_GROUP_SIZES,
    FAYAT_TABLES,
    FAYAT_TIME_POINTS,
    fayat_table,
)
from .power import (
    PowerResult,
    animals_needed,
    noether_n_per_group,
    normal_shift,
    normal_shift_superiority,
    observed_shift,
    power_by_simulation,
)
from .summaries import (
    group_quantiles,
    recovery_table,
    significant_cells,
    with_published,
    published_agreement,
)
from .tables import (
    COLOURS,
    THRESHOLDS,
    against_baseline,
    between_groups,
    format_table,
)

from .cells import __all__ as _cells_all
from .design import __all__ as _design_all
from .effects import __all__ as _effects_all
from .mixed import __all__ as _mixed_all
from .multiple import __all__ as _multiple_all
from .nonparametric import __all__ as _nonparametric_all
from .permutation import __all__ as _permutation_all
from .power import __all__ as _power_all
from .published import __all__ as _published_all
from .summaries import __all__ as _summaries_all
from .tables import __all__ as _tables_all

__all__ = [
    *_design_all,
    *_published_all,
    *_nonparametric_all,
    *_multiple_all,
    *_effects_all,
    *_mixed_all,
    *_permutation_all,
    *_power_all,
    *_cells_all,
    *_tables_all,
    *_summaries_all,
]
