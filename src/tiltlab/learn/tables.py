"""Tables that describe a learned model: its layers, and the settings it was trained with."""

from __future__ import annotations

from collections.abc import Iterable, Mapping

import pandas as pd
import torch

from .._labels import label_columns
from .training import TrainConfig

__all__ = ["layer_settings", "layer_table", "config_table"]


def layer_settings(module: torch.nn.Module) -> str:
    """Describe the shape-defining settings of one layer, in words.

    Parameters
    ----------
    module : torch.nn.Module
        A layer.

    Returns
    -------
    str
        Channels, kernel and dilation of a ``Conv1d``; channels of a
        ``BatchNorm1d``; features in → out of a ``Linear``; ``""`` for any other
        layer (activations, dropout …).

    Examples
    --------
    >>> layer_settings(torch.nn.Conv1d(10, 32, 3, dilation=2))
    '10 → 32 channels, kernel 3, dilation 2'
    >>> layer_settings(torch.nn.Linear(64, 4))
    '64 → 4'
    >>> layer_settings(torch.nn.ReLU())
    ''
    """
    m = module
    if isinstance(m, torch.nn.Conv1d):
        return (
            f"{m.in_channels} → {m.out_channels} channels, kernel {m.kernel_size[0]}, "
            f"dilation {m.dilation[0]}"
        )
    if isinstance(m, torch.nn.BatchNorm1d):
        return f"{m.num_features} channels"
    if isinstance(m, torch.nn.Linear):
        return f"{m.in_features} → {m.out_features}"
    return ""


def layer_table(model: torch.nn.Module) -> pd.DataFrame:
    """One row per leaf layer of a model: its type, settings and number of weights.

    Parameters
    ----------
    model : torch.nn.Module
        E.g. an :class:`~tiltlab.learn.OrientationCNN`.

    Returns
    -------
    pandas.DataFrame
        Indexed by ``"layer"`` (the dotted module name), with the columns ``"type"``
        (class name), ``"settings"`` (:func:`layer_settings`) and ``"weights"``
        (number of parameters, trainable or not), labelled (``attrs["long_name"]``).

    Examples
    --------
    >>> net = torch.nn.Sequential(torch.nn.Linear(3, 2), torch.nn.Tanh())
    >>> layer_table(net)["weights"].tolist()
    [8, 0]
    """
    table = pd.DataFrame(
        [
            {
                "layer": name,
                "type": type(m).__name__,
                "settings": layer_settings(m),
                "weights": sum(p.numel() for p in m.parameters()),
            }
            for name, m in model.named_modules()
            if name and not list(m.children())
        ],
        columns=["layer", "type", "settings", "weights"],
    ).set_index("layer")
    return label_columns(
        table,
        units={"type": "", "settings": "", "weights": "1"},
        long_name={
            "type": "layer type",
            "settings": "settings",
            "weights": "weights (parameters)",
        },
    )


def _setting(v) -> str:
    if isinstance(v, (list, tuple)):
        return ", ".join(map(str, v))
    return f"{v:g}" if isinstance(v, float) else str(v)


def config_table(
    config: TrainConfig,
    meanings: Mapping[str, str] | None = None,
    *,
    skip: Iterable[str] = ("variant", "threads", "seed"),
) -> pd.DataFrame:
    """Tabulate the settings of a training configuration, with what they mean.

    Parameters
    ----------
    config : TrainConfig
        The configuration (e.g. ``TrainConfig.from_dict(run_info["configs"][variant])``).
    meanings : mapping, optional
        Setting name → explanation; a setting without one gets ``""``.
    skip : iterable of str, default ("variant", "threads", "seed")
        Settings left out (by default those that do not change the model's design).

    Returns
    -------
    pandas.DataFrame
        Indexed by ``"setting"`` (in :meth:`TrainConfig.to_dict` order), with the
        columns ``"meaning"`` and ``"value"`` (a string: sequences joined by ``", "``,
        floats in ``%g``), labelled (``attrs["long_name"]``).

    Examples
    --------
    >>> t = config_table(TrainConfig(), {"lr": "learning rate"})
    >>> t.loc["lr", "meaning"], "seed" in t.index
    ('learning rate', False)
    """
    meanings = dict(meanings or {})
    skip = set(skip)
    fields = config.to_dict()
    unknown = (set(meanings) | skip) - set(fields)
    if unknown:
        raise ValueError(
            f"not settings of a TrainConfig: {sorted(unknown)}; they are {list(fields)}"
        )
    table = pd.DataFrame(
        [
            {"setting": k, "meaning": meanings.get(k, ""), "value": _setting(v)}
            for k, v in fields.items()
            if k not in skip
        ],
        columns=["setting", "meaning", "value"],
    ).set_index("setting")
    return label_columns(
        table,
        units={"meaning": "", "value": ""},
        long_name={"meaning": "meaning", "value": "value"},
    )
