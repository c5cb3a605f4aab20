"""Published numbers of Zaheer et al. (2023), transcribed for side-by-side comparison.

Both tables report the mean quaternion angle error (QAE, Eq. 4) of the helmet data's test
sets; the unit is not printed (radians, see :mod:`tiltlab.learn.losses`). Row labels use
this package's names: activations first-hidden-last (Table 2, loss L1 with L(3)), and
total-sample loss (Table 3; ``acos_taylor1`` = L(1) with Eq. 6, ``acos_taylor2`` = with
Eq. 7, ``l1_product`` = L(2), ``l2_product`` = L(3)). The paper's Table 3 has no row 4.

References
----------
.. [1] M. H. Zaheer, S. Y. Yoon and B. K. Higginson, Meas. Control 56:1156–1167, 2023,
   Tables 2 and 3. doi:10.1177/00202940221149062
"""

from __future__ import annotations

import pandas as pd

__all__ = ["ZAHEER_TABLE2", "ZAHEER_TABLE3"]

#: Table 2: test QAE by activation (first, hidden, last).
ZAHEER_TABLE2 = pd.Series(
    {
        "tanh-tanh-tanh": 0.21678,
        "prelu-prelu-prelu": 0.16618,
        "prelu-prelu-tanh": 0.19255,
        "gelu-gelu-gelu": 0.17178,
        "gelu-gelu-tanh": 0.16484,
    },
    name="test_qae",
)

#: Table 3: train and test QAE by total and sample loss.
ZAHEER_TABLE3 = pd.DataFrame(
    {
        "train_qae": {
            "L1-acos_taylor1": 0.3278,
            "L2-acos_taylor1": 0.4634,
            "L2-acos_taylor2": 0.4661,
            "L1-l1_product": 0.3250,
            "L2-l1_product": 0.6163,
            "L1-l2_product": 0.2369,
            "L2-l2_product": 0.2557,
        },
        "test_qae": {
            "L1-acos_taylor1": 0.3542,
            "L2-acos_taylor1": 0.4703,
            "L2-acos_taylor2": 0.4844,
            "L1-l1_product": 0.3489,
            "L2-l1_product": 0.6325,
            "L1-l2_product": 0.2545,
            "L2-l2_product": 0.2669,
        },
    }
)
