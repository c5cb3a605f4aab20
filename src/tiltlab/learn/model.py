r"""The dilated 1-D CNN of Zaheer et al. (2023), Fig. 9, and its learned-gain variant.

Reading of Fig. 9 (the figure gives, per layer, the filter size, the number of filters,
the dilation gap and the activation; its numbers are not legible in the text we have,
so the choices below are ours and stated):

* input layer: a per-sample linear map of the 10 channels to ``channels`` features
  (a 1×1 convolution), activation ``first``;
* hidden layers: ``len(dilations)`` convolutions with kernel ``kernel`` and the given
  dilation gaps, no padding, each followed by batch normalisation (the paper uses it
  "between linear layers") and activation ``hidden``; with kernel 3 and gaps
  (1, 2, 4, 8) the receptive field is 31 samples, about the window;
* output layer: a linear map of the flattened features to 4 numbers with activation
  ``last`` (tanh in the paper's best model). Fig. 5 describes the network as removing
  the bias from the gyro-integrated quaternion; we read this as a residual output,
  :math:`q_t = (q_{\omega,t} + \delta) / \lVert\cdot\rVert` with :math:`\delta` the
  output layer's four numbers, initialised at zero so that training starts from pure
  integration. (In our development runs a network asked for the absolute quaternion
  learned far more slowly and, run in closed loop, drifted.)

The **learned-gain variant** (Eq. 2, proposed but not evaluated in the paper) has the
same body but a single output :math:`\alpha = (1 + \tanh(\cdot))/2 \in (0, 1)` and
returns the complementary-filter blend
:math:`q = (\alpha\, q_{\omega,t} + (1-\alpha)\, q_{\nabla,t}) / \lVert\cdot\rVert`
(Eq. 1), where :math:`q_{\nabla,t}` is the vector-observation (QUEST) orientation at
:math:`t`, sign-aligned with :math:`q_{\omega,t}`.
"""

from __future__ import annotations

import torch
from torch import nn

__all__ = ["ACTIVATIONS", "OrientationCNN"]

#: activation names accepted by :class:`OrientationCNN`
ACTIVATIONS = {"gelu": nn.GELU, "tanh": nn.Tanh, "prelu": nn.PReLU, "relu": nn.ReLU}


def _act(name: str) -> nn.Module:
    if name not in ACTIVATIONS:
        raise ValueError(
            f"activation must be one of {sorted(ACTIVATIONS)}, got {name!r}"
        )
    return ACTIVATIONS[name]()


class OrientationCNN(nn.Module):
    """Window of (batch, 10, T) inputs → unit quaternion (batch, 4).

    Parameters
    ----------
    window : int
        T, samples per window.
    variant : {"quaternion", "gain"}
        Output the quaternion (Eq. 3) or the complementary gain α (Eq. 2).
    channels : int
        Filters per layer.
    kernel : int
        Filter size of the dilated layers.
    dilations : tuple of int
        Dilation gap of each hidden layer.
    activations : (str, str, str)
        First, hidden and last activations (names of :data:`ACTIVATIONS`).
    """

    def __init__(
        self,
        window: int,
        *,
        variant: str = "quaternion",
        channels: int = 32,
        kernel: int = 3,
        dilations: tuple[int, ...] = (1, 2, 4, 8),
        activations: tuple[str, str, str] = ("gelu", "gelu", "tanh"),
    ):
        super().__init__()
        if variant not in ("quaternion", "gain"):
            raise ValueError(f"variant must be 'quaternion' or 'gain', got {variant!r}")
        length = window - (kernel - 1) * sum(dilations)
        if length < 1:
            raise ValueError(
                f"window={window} is shorter than the receptive field "
                f"{1 + (kernel - 1) * sum(dilations)} of kernel={kernel}, "
                f"dilations={dilations}"
            )
        self.variant = variant
        first, hidden, last = activations
        layers: list[nn.Module] = [nn.Conv1d(10, channels, 1), _act(first)]
        for d in dilations:
            layers += [
                nn.Conv1d(channels, channels, kernel, dilation=d),
                nn.BatchNorm1d(channels),
                _act(hidden),
            ]
        self.body = nn.Sequential(*layers)
        self.head = nn.Linear(channels * length, 4 if variant == "quaternion" else 1)
        nn.init.zeros_(self.head.weight)
        nn.init.zeros_(self.head.bias)
        self.last = _act(last)

    def forward(
        self, x: torch.Tensor, q_vec: torch.Tensor | None = None
    ) -> torch.Tensor:
        """Run the network on a batch of windows.

        ``x``: (B, 10, T) with the gyro quaternions in channels 0–3; ``q_vec``:
        (B, 4), the vector-observation orientation at the window's end (``gain``
        variant only).
        """
        h = self.body(x).flatten(1)
        out = self.last(self.head(h))
        q_w = x[:, :4, -1]
        if self.variant == "quaternion":
            q = q_w + out
            return q / q.norm(dim=-1, keepdim=True).clamp_min(1e-8)
        if q_vec is None:
            raise ValueError("the 'gain' variant needs q_vec")
        alpha = (1.0 + out) / 2.0 if isinstance(self.last, nn.Tanh) else out
        sign = torch.where((q_w * q_vec).sum(-1, keepdim=True) < 0, -1.0, 1.0)
        q = alpha * q_w + (1.0 - alpha) * sign * q_vec
        return q / q.norm(dim=-1, keepdim=True).clamp_min(1e-8)
