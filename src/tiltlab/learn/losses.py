r"""Quaternion losses of Zaheer et al. (2023), Eqs. 4–11, in PyTorch.

Per-sample losses for a reference :math:`q` and an estimate :math:`\tilde q` (unit,
scalar first), batched over the leading dimension:

* QAE (Eq. 4): :math:`\theta_e = \arccos(2 (q^\top \tilde q)^2 - 1)`, the rotation
  angle between the two orientations, in **radians** (the unit of the paper's Tables 2–3
  is not printed; their values, 0.16–0.63, are plausible only as radians);
* :math:`L^{(1)}` (Eq. 5), :math:`\arccos(x)` with :math:`x = |q^\top \tilde q|`, exact
  or with the Taylor forms of Eqs. 6–7 (:math:`\pi/2 - x`, :math:`\pi/2 - x - x^3/6`);
* :math:`L^{(2)}` (Eq. 8), the :math:`\mathcal L_1` norm of
  :math:`q^* \otimes \tilde q - (1, 0, 0, 0)`;
* :math:`L^{(3)}` (Eq. 9), the same with the :math:`\mathcal L_2` norm.

Readings of the paper, tested in ``tests/test_learn.py``:

* Eq. 8 prints :math:`q \otimes \tilde q` without the conjugate that Eq. 9 has; without
  it the loss does not vanish at :math:`\tilde q = q`, so the conjugate is used in both.
* :math:`q` and :math:`-q` are the same rotation. All losses here are made
  sign-invariant: :math:`L^{(1)}` through :math:`|q^\top\tilde q|`, :math:`L^{(2)}` and
  :math:`L^{(3)}` by taking the smaller of the values for :math:`\pm\tilde q`.

Totals over the N samples of a batch: :math:`\mathbf L_1 = \sum_i |L_i|` (Eq. 10) and
:math:`\mathbf L_2 = \sqrt{\sum_i L_i^2}` (Eq. 11).
"""

from __future__ import annotations

import math

import torch

__all__ = ["qmul", "qae", "sample_loss", "total_loss", "LOSSES", "TOTALS"]

#: sample losses: name -> description
LOSSES = {
    "acos": "L(1), Eq. 5, exact arccos (clamped)",
    "acos_taylor1": "L(1) with Eq. 6: pi/2 - x",
    "acos_taylor2": "L(1) with Eq. 7: pi/2 - x - x^3/6",
    "l1_product": "L(2), Eq. 8 with the conjugate, L1 norm",
    "l2_product": "L(3), Eq. 9, L2 norm",
}
#: totals: name -> description
TOTALS = {"L1": "sum of |L_i| (Eq. 10)", "L2": "sqrt of the sum of L_i^2 (Eq. 11)"}


def qmul(p: torch.Tensor, q: torch.Tensor) -> torch.Tensor:
    r"""Hamilton product of scalar-first quaternions, broadcast over leading dims.

    Parameters
    ----------
    p, q : torch.Tensor (..., 4)
        Quaternions (w, x, y, z), scalar first; leading dimensions broadcast.

    Returns
    -------
    torch.Tensor (..., 4)
        The product :math:`p \otimes q` (w, x, y, z).
    """
    pw, px, py, pz = p.unbind(-1)
    qw, qx, qy, qz = q.unbind(-1)
    return torch.stack(
        (
            pw * qw - px * qx - py * qy - pz * qz,
            pw * qx + px * qw + py * qz - pz * qy,
            pw * qy - px * qz + py * qw + pz * qx,
            pw * qz + px * qy - py * qx + pz * qw,
        ),
        dim=-1,
    )


def _conj(q: torch.Tensor) -> torch.Tensor:
    return q * torch.tensor([1.0, -1.0, -1.0, -1.0], dtype=q.dtype, device=q.device)


def qae(q_ref: torch.Tensor, q_est: torch.Tensor) -> torch.Tensor:
    """Quaternion angle error (Eq. 4), radians, per sample.

    Parameters
    ----------
    q_ref : torch.Tensor (N, 4)
        Reference unit quaternions (w, x, y, z).
    q_est : torch.Tensor (N, 4)
        Estimated unit quaternions (w, x, y, z), same shape as ``q_ref``.

    Returns
    -------
    torch.Tensor (N,)
        Rotation angle between each pair (rad), in [0, π]; sign-invariant.
    """
    d = (q_ref * q_est).sum(-1)
    return torch.arccos(torch.clamp(2.0 * d * d - 1.0, -1.0, 1.0))


def sample_loss(q_ref: torch.Tensor, q_est: torch.Tensor, kind: str) -> torch.Tensor:
    """Per-sample loss ``kind`` (a key of :data:`LOSSES`).

    Parameters
    ----------
    q_ref, q_est : torch.Tensor (N, 4)
        Reference and estimated unit quaternions (w, x, y, z), as for :func:`qae`.
    kind : str
        Loss name, one of ``"acos"``, ``"acos_taylor1"``, ``"acos_taylor2"``,
        ``"l1_product"``, ``"l2_product"`` (see :data:`LOSSES`).

    Returns
    -------
    torch.Tensor (N,)
        Per-sample loss (rad for the ``"acos"`` forms; dimensionless norms otherwise).

    Raises
    ------
    ValueError
        If ``kind`` is not a key of :data:`LOSSES`.
    """
    if kind not in LOSSES:
        raise ValueError(f"loss must be one of {sorted(LOSSES)}, got {kind!r}")
    if kind.startswith("acos"):
        x = (q_ref * q_est).sum(-1).abs()
        if kind == "acos":
            return torch.arccos(torch.clamp(x, -1.0 + 1e-7, 1.0 - 1e-7))
        if kind == "acos_taylor1":
            return math.pi / 2 - x
        return math.pi / 2 - x - x**3 / 6
    e = qmul(_conj(q_ref), q_est)
    one = torch.zeros_like(e)
    one[..., 0] = 1.0
    if kind == "l1_product":
        plus, minus = (e - one).abs().sum(-1), (e + one).abs().sum(-1)
    else:
        plus, minus = (e - one).norm(dim=-1), (e + one).norm(dim=-1)
    return torch.minimum(plus, minus)


def total_loss(per_sample: torch.Tensor, total: str) -> torch.Tensor:
    """Total of Eq. 10 (``"L1"``) or Eq. 11 (``"L2"``) over a batch.

    Parameters
    ----------
    per_sample : torch.Tensor (N,)
        Per-sample losses, e.g. from :func:`sample_loss`.
    total : {"L1", "L2"}
        ``"L1"``: sum of absolute values (Eq. 10); ``"L2"``: square root of the sum of
        squares (Eq. 11, with 1e-12 added under the root for a finite gradient).

    Returns
    -------
    torch.Tensor
        Scalar (0-d) total loss.

    Raises
    ------
    ValueError
        If ``total`` is not a key of :data:`TOTALS`.
    """
    if total == "L1":
        return per_sample.abs().sum()
    if total == "L2":
        return torch.sqrt((per_sample * per_sample).sum() + 1e-12)
    raise ValueError(f"total must be one of {sorted(TOTALS)}, got {total!r}")
