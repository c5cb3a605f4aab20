r"""Train the learned orientation estimators and run them in closed loop.

Training, closed-loop inference and grouped cross-validation of the learned
orientation estimators.

Everything is seeded and runs deterministically on the CPU
(``torch.use_deterministic_algorithms``, a fixed number of threads): the same
configuration gives the same weights bit for bit, which a test checks.

Augmentations (Zaheer et al. 2023, "Data augmentation"), drawn per window:

* Gaussian noise on the scaled specific force and field;
* a static bias on each (constant over the window);
* a random rotation of the integrator's initial orientation :math:`q_0` (angle
  :math:`\mathcal N(0, \sigma_0)` about a random axis);
* a random rotation :math:`c` of the sensor frame applied consistently to everything:
  vectors :math:`b \to R(c)\,b`, orientations :math:`q \to q \otimes c^*` (so the
  gyro-integrated window :math:`q_\omega \to q_\omega \otimes c^*`), as if the IMU had
  been mounted differently.
"""

from __future__ import annotations

import copy
import dataclasses
import math
import time
from collections.abc import Callable, Sequence as Seq
from dataclasses import dataclass
from typing import Any

import numpy as np
import torch

from .. import _deprecate
from .. import _validate as _v
from .data import Sequence, window_ends
from .losses import LOSSES, TOTALS, qae, qmul, sample_loss, total_loss
from .model import ACTIVATIONS, OrientationCNN
from .optim import radam_lookahead

__all__ = [
    "TrainConfig",
    "build_model",
    "train",
    "validation_error",
    "closed_loop_estimate",
    "closed_loop_estimates",
    "run",
]


@dataclass(frozen=True)
class TrainConfig:
    """Everything that defines a trained model (stored with its weights as JSON).

    ``window_s`` is converted to a window of ``round(window_s * fs)`` samples: the
    paper's 32 samples at 250 Hz are 0.128 s, i.e. 37 samples at BROAD's 285.7 Hz.
    ``patience`` (epochs) stops training early once the validation error has not
    improved for that many epochs (0: train every epoch); it needs validation
    sequences (:func:`train`).
    """

    variant: str = "quaternion"
    window_s: float = 0.128
    channels: int = 32
    kernel: int = 3
    dilations: tuple[int, ...] = (1, 2, 4, 8)
    activations: tuple[str, str, str] = ("gelu", "gelu", "tanh")
    loss: str = "l2_product"
    total: str = "L1"
    epochs: int = 6
    batch: int = 256
    lr: float = 1e-3
    lookahead_k: int = 5
    lookahead_alpha: float = 0.5
    stride: int = 8
    acc_scale: float = 9.81
    mag_scale: float = 50.0
    noise_acc: float = 0.01
    noise_mag: float = 0.01
    bias_acc: float = 0.01
    bias_mag: float = 0.02
    init_deg: float = 8.0
    mount_deg: float = 10.0
    seed: int = 0
    threads: int = 1
    patience: int = 0

    def __post_init__(self):
        """Check every field."""
        if self.variant not in ("quaternion", "gain"):
            raise ValueError(
                f"variant must be 'quaternion' or 'gain', got {self.variant!r}"
            )
        if self.loss not in LOSSES:
            raise ValueError(f"loss must be one of {sorted(LOSSES)}, got {self.loss!r}")
        if self.total not in TOTALS:
            raise ValueError(
                f"total must be one of {sorted(TOTALS)}, got {self.total!r}"
            )
        for a in self.activations:
            if a not in ACTIVATIONS:
                raise ValueError(
                    f"activations must be names of {sorted(ACTIVATIONS)}, got {a!r}"
                )
        for name in ("window_s", "lr", "acc_scale", "mag_scale"):
            _v.positive(getattr(self, name), name)
        for name in ("noise_acc", "noise_mag", "bias_acc", "bias_mag", "init_deg"):
            _v.nonnegative(getattr(self, name), name)
        for name in ("channels", "kernel", "epochs", "batch", "stride", "threads"):
            _v.integer(getattr(self, name), name, minimum=1)
        _v.integer(self.seed, "seed", minimum=0)
        _v.integer(self.patience, "patience", minimum=0)
        object.__setattr__(self, "dilations", tuple(int(d) for d in self.dilations))
        object.__setattr__(self, "activations", tuple(self.activations))

    def window(self, fs: float) -> int:
        """Return the window length in samples at the sampling rate ``fs`` (Hz)."""
        return int(round(self.window_s * _v.check_fs(fs)))

    def to_dict(self) -> dict[str, Any]:
        """Return the configuration as a JSON-able dict."""
        return dataclasses.asdict(self)

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> TrainConfig:
        """Build a configuration from :meth:`to_dict` output."""
        d = dict(d)
        d["dilations"] = tuple(d["dilations"])
        d["activations"] = tuple(d["activations"])
        return cls(**d)


def build_model(config: TrainConfig, fs: float) -> OrientationCNN:
    """Build a new (untrained) network for a configuration and sampling rate.

    Parameters
    ----------
    config : TrainConfig
        Architecture: variant, channels, kernel, dilations, activations and window
        duration ``window_s`` (s).
    fs : float
        Sampling rate (Hz); the window is ``round(window_s * fs)`` samples.

    Returns
    -------
    OrientationCNN
        The network, with freshly initialised weights.
    """
    return OrientationCNN(
        config.window(fs),
        variant=config.variant,
        channels=config.channels,
        kernel=config.kernel,
        dilations=config.dilations,
        activations=config.activations,
    )


# ---------------------------------------------------------------- batches


class _Stack:
    """Training sequences concatenated, as tensors, with the valid window ends."""

    def __init__(self, seqs: Seq[Sequence], window: int, stride: int):
        self.window = window
        offs, ends = 0, []
        for s in seqs:
            ends.append(window_ends(s, window, stride) + offs)
            offs += len(s)

        def cat(name: str) -> torch.Tensor:
            return torch.from_numpy(np.concatenate([getattr(s, name) for s in seqs]))

        self.Q, self.acc, self.mag = cat("Q"), cat("acc"), cat("mag")
        self.q_vec, self.q_ref = cat("q_vec"), cat("q_ref")
        self.ends = torch.from_numpy(np.concatenate(ends))


def _conj(q: torch.Tensor) -> torch.Tensor:
    return q * torch.tensor([1.0, -1.0, -1.0, -1.0])


def _axis_angle(axis: torch.Tensor, angle: torch.Tensor) -> torch.Tensor:
    axis = axis / axis.norm(dim=-1, keepdim=True).clamp_min(1e-12)
    return torch.cat(
        [torch.cos(angle / 2)[:, None], torch.sin(angle / 2)[:, None] * axis], dim=-1
    )


def _rotate(q: torch.Tensor, v: torch.Tensor) -> torch.Tensor:
    """Rotate vectors v (B, T, 3) by quaternions q (B, 4)."""
    qv = torch.cat([torch.zeros_like(v[..., :1]), v], dim=-1)
    qq = q[:, None, :].expand(-1, v.shape[1], -1)
    return qmul(qmul(qq, qv), _conj(qq))[..., 1:]


def _canonical(q: torch.Tensor) -> torch.Tensor:
    return torch.where(q[..., :1] < 0, -q, q)


def _indices(ends: torch.Tensor, window: int) -> torch.Tensor:
    """(B, T) sample indices of the windows ending at ``ends``."""
    return ends[:, None] + torch.arange(-window + 1, 1)[None, :]


def _inputs(
    Q: torch.Tensor,
    acc_w: torch.Tensor,
    mag_w: torch.Tensor,
    ends: torch.Tensor,
    q0: torch.Tensor,
    window: int,
) -> torch.Tensor:
    """Assemble the (B, 10, T) network inputs of windows ending at ``ends``.

    (B, 10, T) network inputs for windows ending at ``ends`` (windowed ``acc_w`` and
    ``mag_w``, (B, T, 3)) from initial orientations ``q0`` (B, 4) at ``ends - window``.
    """
    dq = qmul(_conj(Q[ends - window])[:, None, :], Q[_indices(ends, window)])
    q_w = qmul(_canonical(q0)[:, None, :], dq)
    return torch.cat([q_w, acc_w, mag_w], dim=-1).transpose(1, 2)


def _batch(stack: _Stack, ends: torch.Tensor, cfg: TrainConfig, g: torch.Generator):
    """Augmented inputs, q_vec and targets for one batch."""
    w = stack.window
    n = ends.numel()
    k = _indices(ends, w)

    def gauss(*shape, scale):
        return torch.randn(*shape, generator=g) * scale

    ang0 = gauss(n, scale=math.radians(cfg.init_deg))
    noise0 = _axis_angle(gauss(n, 3, scale=1.0), ang0)
    q0 = qmul(noise0, stack.q_ref[ends - w])
    acc = (
        stack.acc[k]
        + gauss(n, w, 3, scale=cfg.noise_acc)
        + gauss(n, 1, 3, scale=cfg.bias_acc)
    )
    mag = (
        stack.mag[k]
        + gauss(n, w, 3, scale=cfg.noise_mag)
        + gauss(n, 1, 3, scale=cfg.bias_mag)
    )
    x = _inputs(stack.Q, acc, mag, ends, q0, w)
    target = stack.q_ref[ends]
    q_vec = stack.q_vec[ends]
    if cfg.mount_deg > 0:
        c = _axis_angle(
            gauss(n, 3, scale=1.0), gauss(n, scale=math.radians(cfg.mount_deg))
        )
        cc = _conj(c)
        q_w = qmul(x[:, :4, :].transpose(1, 2), cc[:, None, :])
        x = torch.cat([q_w, _rotate(c, acc), _rotate(c, mag)], dim=-1).transpose(1, 2)
        target = qmul(target, cc)
        q_vec = qmul(q_vec, cc)
    return x.contiguous(), q_vec, target


# ---------------------------------------------------------------- training


def _seed(cfg: TrainConfig) -> torch.Generator:
    torch.manual_seed(cfg.seed)
    torch.set_num_threads(cfg.threads)
    torch.use_deterministic_algorithms(True)
    g = torch.Generator()
    g.manual_seed(cfg.seed)
    return g


def validation_error(
    model: OrientationCNN, sequences: Seq[Sequence], config: TrainConfig
) -> float:
    """Mean closed-loop QAE (degrees) of ``model`` over validation ``sequences``.

    Each sequence is estimated in closed loop (:func:`closed_loop_estimate`), as the
    held-out trials are, and the QAE is averaged over all samples with a reference.

    Parameters
    ----------
    model : OrientationCNN
        The network being trained.
    sequences : sequence of Sequence
        Validation data, each with ``q_ref``.
    config : TrainConfig
        The model's configuration (its window).

    Returns
    -------
    float
        Mean QAE (deg) over every sample with a finite reference.
    """
    total, count = 0.0, 0
    for seq in sequences:
        q = torch.from_numpy(closed_loop_estimate(model, seq, config))
        ref = torch.from_numpy(np.asarray(seq.q_ref, dtype=np.float64))
        ok = torch.isfinite(ref).all(-1)
        err = qae(ref[ok], q[ok])
        total += float(err.sum())
        count += int(ok.sum())
    if count == 0:
        raise ValueError("no validation sample has a reference orientation")
    return math.degrees(total / count)


def train(
    sequences: Seq[Sequence],
    config: TrainConfig,
    *,
    validation: Seq[Sequence] | None = None,
    max_steps: int | None = None,
    progress: Callable[[str], None] | None = None,
) -> tuple[OrientationCNN, list[dict[str, float]]]:
    """Train a model on ``sequences`` (each with ``q_ref``).

    With ``validation`` sequences, the closed-loop validation error
    (:func:`validation_error`) is measured after every epoch, the weights of the best
    epoch are returned, and with ``config.patience`` > 0 training stops once that
    many epochs have passed without improvement (early stopping). The validation
    pass draws no random numbers, so the training steps are the same with or without
    it.

    Parameters
    ----------
    sequences : sequence of Sequence
        Training data (:func:`tiltlab.learn.sequence`), all at the same ``fs``.
    validation : sequence of Sequence, optional
        Validation data (trials kept out of ``sequences``), same ``fs``.
    config : TrainConfig
        Model and training settings: the architecture and window (``window_s``, s),
        ``epochs``, ``batch``, ``stride``, ``lr`` and Lookahead settings, the loss, the
        augmentation noise and biases, ``seed`` and ``threads``.
    max_steps : int, optional
        Stop after this many optimiser steps (tests, quick looks).
    progress : callable, optional
        Called with one line per epoch.

    Returns
    -------
    model : OrientationCNN
        In evaluation mode.
    history : list of dict
        Per epoch: ``epoch``, ``loss`` (mean total loss per batch), ``qae_deg`` (mean
        QAE of the training windows, degrees), ``seconds``; with ``validation`` also
        ``val_qae_deg`` (closed-loop validation QAE, degrees) and ``best`` (whether
        this epoch's weights are the ones returned so far).
    """
    if not sequences:
        raise ValueError("sequences is empty")
    fs = sequences[0].fs
    validation = list(validation or [])
    if any(abs(s.fs - fs) > 1e-9 * fs for s in [*sequences, *validation]):
        raise ValueError("all training and validation sequences must have the same fs")
    if config.patience and not validation:
        raise ValueError(
            f"patience = {config.patience} epochs needs validation sequences to "
            "decide when to stop (pass validation=[...])"
        )
    g = _seed(config)
    window = config.window(fs)
    stack = _Stack(sequences, window, config.stride)
    if stack.ends.numel() == 0:
        raise ValueError("no training window has a valid reference at both ends")
    model = build_model(config, fs)
    opt = radam_lookahead(
        model.parameters(),
        lr=config.lr,
        k=config.lookahead_k,
        alpha=config.lookahead_alpha,
    )
    history: list[dict[str, float]] = []
    steps = 0
    best: tuple[float, int, dict] | None = None  # (error, epoch, weights)
    for epoch in range(config.epochs):
        model.train()
        t0 = time.perf_counter()
        order = stack.ends[torch.randperm(stack.ends.numel(), generator=g)]
        losses, errs = [], []
        for b in range(0, order.numel(), config.batch):
            ends = order[b : b + config.batch]
            if ends.numel() < 2:
                continue
            x, q_vec, target = _batch(stack, ends, config, g)
            out = model(x, q_vec)
            loss = total_loss(sample_loss(target, out, config.loss), config.total)
            opt.zero_grad()
            loss.backward()
            opt.step()
            losses.append(float(loss.detach()))
            errs.append(float(qae(target, out.detach()).mean()))
            steps += 1
            if max_steps is not None and steps >= max_steps:
                break
        history.append(
            {
                "epoch": epoch + 1,
                "loss": float(np.mean(losses)),
                "qae_deg": math.degrees(float(np.mean(errs))),
                "seconds": time.perf_counter() - t0,
            }
        )
        if validation:
            err = validation_error(model, validation, config)
            improved = best is None or err < best[0]
            if improved:
                best = (err, epoch, copy.deepcopy(model.state_dict()))
            history[-1] |= {"val_qae_deg": err, "best": improved}
        if progress is not None:
            h = history[-1]
            val = f", validation {h['val_qae_deg']:.2f} deg" if validation else ""
            progress(
                f"epoch {epoch + 1}/{config.epochs}: loss {h['loss']:.4g}, "
                f"QAE {h['qae_deg']:.2f} deg{val}, {h['seconds']:.0f} s"
            )
        if max_steps is not None and steps >= max_steps:
            break
        if best is not None and config.patience and epoch - best[1] >= config.patience:
            break
    if best is not None:
        model.load_state_dict(best[2])
    model.eval()
    return model, history


# ---------------------------------------------------------------- inference


@torch.no_grad()
def closed_loop_estimate(
    model: OrientationCNN, seq: Sequence, config: TrainConfig
) -> np.ndarray:
    r"""Estimate the orientation of a whole sequence in closed loop, (N, 4) float64.

    The first :math:`T` samples integrate the gyroscope from the vector-observation
    orientation of the first window (QUEST initialisation); from then on, the estimate
    at :math:`t` is the network's output for the window starting at :math:`t-T` with
    the integrator started from its own estimate there. Windows are evaluated in
    blocks of :math:`T` consecutive outputs, one batch per block.

    Parameters
    ----------
    model : OrientationCNN
        Trained network (set to evaluation mode).
    seq : Sequence
        Arrays of the recording (:func:`tiltlab.learn.data.sequence`).
    config : TrainConfig
        Configuration the model was trained with (its window duration, s).

    Returns
    -------
    numpy.ndarray (N, 4)
        Unit quaternions (w, x, y, z), float64, one per sample of ``seq``.

    Raises
    ------
    ValueError
        A sequence of at most :math:`T + 1` samples: the network's first output is at
        sample :math:`T + 1`, so a shorter recording would be pure gyroscope
        integration, never the model's estimate. The message gives both lengths.
    """
    return closed_loop_estimates(model, [seq], config)[0]


@torch.no_grad()
def closed_loop_estimates(
    model: OrientationCNN, sequences: Seq[Sequence], config: TrainConfig
) -> list[np.ndarray]:
    r"""Estimate several sequences in closed loop at once, batched across sequences.

    The same recursion as :func:`closed_loop_estimate`, which is sequential in time
    only: at every block of :math:`T` outputs, the windows of all sequences that
    still have samples there go through the network in one batch. Each sequence's
    estimate depends on its own samples only (the network has no batch coupling in
    evaluation mode), so the result equals estimating each sequence alone up to the
    float32 rounding of a differently sized batch.

    Parameters
    ----------
    model : OrientationCNN
        Trained network (set to evaluation mode).
    sequences : sequence of Sequence
        Arrays of the recordings (:func:`tiltlab.learn.data.sequence`), all at the
        same sampling rate; lengths may differ.
    config : TrainConfig
        Configuration the model was trained with.

    Returns
    -------
    list of numpy.ndarray (N_i, 4)
        Unit quaternions (w, x, y, z), float64, one array per sequence, in order.

    Raises
    ------
    ValueError
        Sequences at different sampling rates, or one too short for the window (see
        :func:`closed_loop_estimate`).

    Examples
    --------
    >>> import numpy as np
    >>> from tiltlab.learn import Sequence, TrainConfig, build_model
    >>> cfg = TrainConfig(window_s=0.128)
    >>> model = build_model(cfg, 300.0)
    >>> def at_rest(n):  # identity orientation, gravity and field along z
    ...     q = np.tile(np.float32([1, 0, 0, 0]), (n, 1))
    ...     v = np.tile(np.float32([0, 0, 1]), (n, 1))
    ...     return Sequence(q, v, v, q, None, 300.0, "rest")
    >>> out = closed_loop_estimates(model, [at_rest(50), at_rest(80)], cfg)
    >>> [q.shape for q in out]
    [(50, 4), (80, 4)]
    """
    model.eval()
    seqs = list(sequences)
    if not seqs:
        return []
    fs = seqs[0].fs
    other = [s.fs for s in seqs if abs(s.fs - fs) > 1e-9 * fs]
    if other:
        raise ValueError(
            f"the sequences have different sampling rates ({fs:.6g} and "
            f"{other[0]:.6g} Hz): a batch runs one model at one rate"
        )
    window = config.window(fs)
    for seq in seqs:
        n = len(seq)
        if n < window + 2:
            raise ValueError(
                f"the recording has {n} samples ({n / fs:.3g} s at {fs:g} Hz), but "
                f"the model's window is {window} samples (window_s = "
                f"{config.window_s:g} s): the network first runs at sample "
                f"{window + 1}, so at least {window + 2} samples are needed (a "
                "shorter recording would only integrate the gyroscope)"
            )
    arrays, outs = [], []
    for seq in seqs:
        Q = torch.from_numpy(seq.Q)
        q_vec = torch.from_numpy(seq.q_vec)
        out = torch.empty(len(seq), 4)
        head = window + 1
        q_init = _canonical(q_vec[:head].mean(0, keepdim=True))
        q_init = q_init / q_init.norm()
        out[:head] = qmul(q_init, qmul(_conj(Q[:1]), Q[:head]))
        arrays.append((Q, torch.from_numpy(seq.acc), torch.from_numpy(seq.mag), q_vec))
        outs.append(out)
    for b in range(window + 1, max(len(s) for s in seqs), window):
        live = [i for i, s in enumerate(seqs) if b < len(s)]
        parts, qv, spans = [], [], []
        for i in live:
            Q, acc, mag, q_vec = arrays[i]
            ends = torch.arange(b, min(b + window, len(seqs[i])))
            k = _indices(ends, window)
            parts.append(
                _inputs(Q, acc[k], mag[k], ends, outs[i][ends - window], window)
            )
            qv.append(q_vec[ends])
            spans.append(ends)
        if len(live) == 1:
            y = model(parts[0], qv[0])
        else:
            y = model(torch.cat(parts), torch.cat(qv))
        start = 0
        for i, ends in zip(live, spans):
            outs[i][ends] = y[start : start + len(ends)]
            start += len(ends)
    return [_canonical(out).double().numpy() for out in outs]


#: the old names, for one release
run = _deprecate.alias(closed_loop_estimate, "run")
