r"""Wrap any PyTorch optimiser in Lookahead (Zhang et al. 2019).

Lookahead (Zhang et al. 2019) around any PyTorch optimiser; with
``torch.optim.RAdam`` (Liu et al. 2020) inside it is the "RAdam + Lookahead" of Zaheer
et al. (2023).

Every ``k`` steps of the inner ("fast") optimiser the slow weights move a fraction
:math:`\alpha` towards the fast ones, :math:`\phi \leftarrow \phi + \alpha(\theta -
\phi)`, and the fast weights restart from them, :math:`\theta \leftarrow \phi`.

References
----------
.. [1] M. R. Zhang, J. Lucas, G. Hinton and J. Ba, "Lookahead optimizer: k steps
   forward, 1 step back", NeurIPS 2019. arXiv:1907.08610
.. [2] L. Liu et al., "On the variance of the adaptive learning rate and beyond",
   ICLR 2020. arXiv:1908.03265
"""

from __future__ import annotations

import torch

__all__ = ["Lookahead", "radam_lookahead"]


class Lookahead:
    """Wrap an optimiser in Lookahead.

    Lookahead wrapper: ``step()`` runs the inner optimiser and, every ``k`` calls,
    the slow-weight update.

    Parameters
    ----------
    inner : torch.optim.Optimizer
        The fast optimiser.
    k : int
        Synchronisation period (steps).
    alpha : float
        Slow step size in (0, 1].
    """

    def __init__(self, inner: torch.optim.Optimizer, *, k: int = 5, alpha: float = 0.5):
        if int(k) < 1:
            raise ValueError(f"k must be a positive integer, got {k!r}")
        if not 0.0 < float(alpha) <= 1.0:
            raise ValueError(f"alpha must be in (0, 1], got {alpha!r}")
        self.inner = inner
        self.k = int(k)
        self.alpha = float(alpha)
        self._count = 0
        self._slow = [
            [p.detach().clone() for p in group["params"]]
            for group in inner.param_groups
        ]

    def zero_grad(self, set_to_none: bool = True) -> None:
        """Zero the inner optimiser's gradients."""
        self.inner.zero_grad(set_to_none=set_to_none)

    @torch.no_grad()
    def step(self) -> None:
        """Step the inner optimiser; every ``k`` steps, update the slow weights."""
        self.inner.step()
        self._count += 1
        if self._count % self.k:
            return
        for group, slow in zip(self.inner.param_groups, self._slow, strict=True):
            for p, s in zip(group["params"], slow, strict=True):
                s.add_(p - s, alpha=self.alpha)
                p.copy_(s)


def radam_lookahead(params, *, lr: float, k: int = 5, alpha: float = 0.5) -> Lookahead:
    """``Lookahead(torch.optim.RAdam(params, lr=lr), k=k, alpha=alpha)``.

    Parameters
    ----------
    params : iterable of torch.Tensor or dict
        Parameters (or parameter groups) to optimise, as for ``torch.optim.RAdam``.
    lr : float
        Learning rate of the inner RAdam optimiser.
    k : int, default 5
        Lookahead synchronisation period (inner steps).
    alpha : float, default 0.5
        Slow-weight step size, in (0, 1].

    Returns
    -------
    Lookahead
        The Lookahead optimiser wrapping RAdam.
    """
    return Lookahead(torch.optim.RAdam(params, lr=lr), k=k, alpha=alpha)
