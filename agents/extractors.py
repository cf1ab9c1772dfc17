"""Feature extractors for map observations: a small CNN for a long, narrow,
multi-channel costmap, alone or beside a vector.

A ship environment's ``obs_type="costmap"`` observation is a float32
``Box`` of shape (C, H, W): C channels of H cells along the goal direction
by W across the channel (ShipNavigation-v1: 3 × 64 × 40, 5 m cells). Its
values are already scaled by the environment (about 0 to 5), so nothing
here rescales them: stable-baselines3 divides an observation by 255 only
when it is an image space (``is_image_space``: a uint8 ``Box`` with bounds
0 and 255), which a float32 map is not, and the training leaves maps out
of ``VecNormalize`` (:func:`agents.envs.normalize_for_space`).

* :class:`CostmapCNN` — for a ``Box`` (C, H, W): strided convolutions that
  halve both axes at each step, so that the map keeps its proportions
  (64 × 40 → 32 × 20 → 16 × 10 → 8 × 5), a 1 × 1 convolution that
  narrows the channels before the flatten, and a linear layer to
  ``features_dim``; ReLU after each. On ShipNavigation-v1's map the
  default has 97 680 parameters, most of them in the last layer (each of
  the 8 × 5 cells, about 40 m on a side, keeps its place in the flatten).
* :class:`CostmapCombined` — for a ``Dict`` of maps (3-D ``Box``) and
  vectors (other ``Box``): the CNN on each map and the flattened vector
  (or a small MLP on it, ``vector_dim`` > 0), concatenated; the policy of
  SB3's ``MultiInputPolicy`` with it.

In a hyperparameter file they are named in ``policy_kwargs``::

    policy: MultiInputPolicy
    policy_kwargs:
      features_extractor_class: CostmapCombined
      features_extractor_kwargs: {cnn_dim: 128}

(:func:`extractor_class` resolves the names of :data:`EXTRACTORS`; no other
name is evaluated.)
"""
from __future__ import annotations

from collections.abc import Sequence

import gymnasium as gym
import numpy as np
import torch
from stable_baselines3.common.torch_layers import (BaseFeaturesExtractor, CombinedExtractor,
                                                   FlattenExtractor, NatureCNN)
from torch import nn

from .observations import is_map_space

__all__ = ["DEFAULT_LAYERS", "CostmapCNN", "CostmapCombined", "EXTRACTORS", "extractor_class",
           "conv_output_shape"]

#: the default convolutions: (output channels, kernel, stride) each, padded by
#: kernel // 2, so that a stride of 2 halves an axis (rounding up)
DEFAULT_LAYERS = ((16, 5, 2), (32, 3, 2), (32, 3, 2), (16, 1, 1))


def conv_output_shape(shape: Sequence[int], layers: Sequence[Sequence[int]]) -> tuple[int, ...]:
    """The (channels, rows, columns) after ``layers`` (see :class:`CostmapCNN`)
    on a map of ``shape``: each axis of n cells becomes
    ``(n + 2 * (k // 2) - k) // s + 1``."""
    c, h, w = (int(n) for n in shape)
    for out, k, s in layers:
        pad = k // 2
        c, h, w = out, (h + 2 * pad - k) // s + 1, (w + 2 * pad - k) // s + 1
    return c, h, w


def _checked_layers(layers) -> tuple[tuple[int, int, int], ...]:
    try:
        checked = tuple(tuple(int(v) for v in layer) for layer in layers)
    except (TypeError, ValueError):
        raise ValueError(f"layers must be (channels, kernel, stride) triples, got "
                         f"{layers!r}") from None
    if not checked or any(len(layer) != 3 or min(layer) < 1 or layer[1] % 2 == 0
                          for layer in checked):
        raise ValueError(f"layers must be (channels, kernel, stride) triples of positive "
                         f"integers with odd kernels, got {layers!r}")
    return checked


class CostmapCNN(BaseFeaturesExtractor):
    """A small CNN for a float (C, H, W) map (see the module's text).

    Parameters
    ----------
    observation_space : gymnasium.spaces.Box
        Three axes (channels first), a floating dtype: the values are used
        as they come (no division by 255).
    features_dim : int
        Outputs of the last (linear) layer.
    layers : sequence of (channels, kernel, stride)
        The convolutions, each padded by ``kernel // 2`` and followed by a
        ReLU; kernels odd. Default :data:`DEFAULT_LAYERS`.

    Raises
    ------
    ValueError
        For a space that is not a 3-axis float ``Box``, a bad layer, or a
        ``features_dim`` < 1.
    """

    def __init__(self, observation_space: gym.spaces.Box, features_dim: int = 128,
                 layers: Sequence[Sequence[int]] = DEFAULT_LAYERS):
        if not is_map_space(observation_space):
            raise ValueError(f"CostmapCNN takes a Box of shape (channels, rows, columns), got "
                             f"{observation_space}")
        if not np.issubdtype(observation_space.dtype, np.floating):
            raise ValueError(f"CostmapCNN takes a float map (scaled by the environment), got "
                             f"dtype {observation_space.dtype}; for a uint8 image use SB3's "
                             f"NatureCNN (CnnPolicy)")
        if isinstance(features_dim, bool) or not isinstance(features_dim, (int, np.integer)) \
                or features_dim < 1:
            raise ValueError(f"features_dim must be an integer >= 1, got {features_dim!r}")
        layers = _checked_layers(layers)
        super().__init__(observation_space, int(features_dim))
        modules: list[nn.Module] = []
        channels = observation_space.shape[0]
        for out, k, s in layers:
            modules += [nn.Conv2d(channels, out, kernel_size=k, stride=s, padding=k // 2),
                        nn.ReLU()]
            channels = out
        self.cnn = nn.Sequential(*modules, nn.Flatten())
        flat = int(np.prod(conv_output_shape(observation_space.shape, layers)))
        self.linear = nn.Sequential(nn.Linear(flat, int(features_dim)), nn.ReLU())

    def forward(self, observations: torch.Tensor) -> torch.Tensor:
        return self.linear(self.cnn(observations))


class CostmapCombined(BaseFeaturesExtractor):
    """:class:`CostmapCNN` on each map of a ``Dict`` observation, beside its
    vectors, concatenated (SB3's ``MultiInputPolicy``).

    Parameters
    ----------
    observation_space : gymnasium.spaces.Dict
        Maps (3-axis float ``Box``, e.g. ``"costmap"``) and vectors (any
        other ``Box``, e.g. ``"vector"``); at least one map.
    cnn_dim : int
        Features of each map (``features_dim`` of its CNN).
    vector_dim : int
        0 (default): each vector is flattened as it is; > 0: a linear layer
        and a ReLU to this many features.
    layers : sequence of (channels, kernel, stride)
        The convolutions of each map's CNN (:class:`CostmapCNN`).

    Raises
    ------
    ValueError
        For a space that is not a ``Dict``, a part that is not a ``Box``, a
        ``Dict`` without a map, or a bad dimension.
    """

    def __init__(self, observation_space: gym.spaces.Dict, cnn_dim: int = 128,
                 vector_dim: int = 0, layers: Sequence[Sequence[int]] = DEFAULT_LAYERS):
        if not isinstance(observation_space, gym.spaces.Dict):
            raise ValueError(f"CostmapCombined takes a Dict observation space, got "
                             f"{observation_space}")
        bad = {k: type(s).__name__ for k, s in observation_space.spaces.items()
               if not isinstance(s, gym.spaces.Box)}
        if bad:
            raise ValueError(f"CostmapCombined takes a Dict of Box spaces; not a Box: {bad}")
        if not any(is_map_space(s) for s in observation_space.spaces.values()):
            raise ValueError(f"CostmapCombined needs a map (a Box of shape (channels, rows, "
                             f"columns)) in the Dict, got {observation_space}")
        if isinstance(vector_dim, bool) or not isinstance(vector_dim, (int, np.integer)) \
                or vector_dim < 0:
            raise ValueError(f"vector_dim must be an integer >= 0, got {vector_dim!r}")
        parts: dict[str, nn.Module] = {}
        total = 0
        for key, space in observation_space.spaces.items():
            if is_map_space(space):
                parts[key] = CostmapCNN(space, features_dim=cnn_dim, layers=layers)
                total += parts[key].features_dim
            else:
                size = int(np.prod(space.shape))
                parts[key] = (nn.Flatten() if vector_dim == 0 else
                              nn.Sequential(nn.Flatten(), nn.Linear(size, int(vector_dim)),
                                            nn.ReLU()))
                total += size if vector_dim == 0 else int(vector_dim)
        super().__init__(observation_space, total)
        self.extractors = nn.ModuleDict(parts)

    def forward(self, observations: dict) -> torch.Tensor:
        return torch.cat([net(observations[key]) for key, net in self.extractors.items()],
                         dim=1)


#: the feature extractors a hyperparameter file may name
#: (``policy_kwargs.features_extractor_class``)
EXTRACTORS = {cls.__name__: cls for cls in (CostmapCNN, CostmapCombined, FlattenExtractor,
                                            CombinedExtractor, NatureCNN)}


def extractor_class(name):
    """The feature extractor class named ``name`` (a key of :data:`EXTRACTORS`);
    a class is returned as it is.

    Raises
    ------
    ValueError
        For another name.
    """
    if isinstance(name, type):
        return name
    if name not in EXTRACTORS:
        raise ValueError(f"unknown features_extractor_class {name!r}; valid: "
                         f"{', '.join(EXTRACTORS)}")
    return EXTRACTORS[name]
