"""A critic that sees more than the actor: an asymmetric actor-critic
(Pinto et al. 2018, "Asymmetric actor critic for image-based robot
learning").

In training, a simulator can tell the critic what the policy will never
see when it is played: here, what the ice ahead costs, read from every
floe. The critic's value then varies with the field as the returns do, so
the advantages it gives the actor carry less of the field's luck. Only the
critic reads the privileged signals; the actor, the policy that is played,
reads the observation without them.

:class:`PrivilegedCriticPolicy` is SB3's ``MultiInputActorCriticPolicy``
with features of its own for the critic (``share_features_extractor``
False): the actor's features extractor is built on the ``Dict``
observation without the privileged key
(:data:`agents.waypoint_follower.PRIVILEGED`), and the critic's is
:class:`PrivilegedFeatures`, the same extractor of the same public
observation plus a linear map of the privileged vector, which
:func:`agents.waypoint_rl.finetune` starts at zero so that the critic
starts as the student's.
"""
from __future__ import annotations

import gymnasium as gym
import torch
from stable_baselines3.common.policies import MultiInputActorCriticPolicy
from stable_baselines3.common.torch_layers import BaseFeaturesExtractor

from .waypoint_follower import PRIVILEGED

__all__ = ["public_space", "PrivilegedFeatures", "PrivilegedCriticPolicy"]


def public_space(space: gym.spaces.Dict) -> gym.spaces.Dict:
    """``space`` without its privileged part (:data:`PRIVILEGED`)."""
    if not isinstance(space, gym.spaces.Dict) or PRIVILEGED not in space.spaces:
        raise ValueError(f"a privileged critic needs a Dict observation with a "
                         f"{PRIVILEGED!r} vector, got {space}")
    return gym.spaces.Dict({k: v for k, v in space.spaces.items() if k != PRIVILEGED})


class PrivilegedFeatures(BaseFeaturesExtractor):
    """``base_class``'s features of the public observation plus a linear
    map of the privileged vector (``inject``), of the same dimension.

    Parameters
    ----------
    observation_space : gymnasium.spaces.Dict
        With a 1-axis ``Box`` under :data:`PRIVILEGED`.
    base_class : type of BaseFeaturesExtractor
        The actor's features extractor, built on :func:`public_space`.
    base_kwargs : dict
        Its keywords.
    """

    def __init__(self, observation_space: gym.spaces.Dict, base_class, base_kwargs: dict):
        base = base_class(public_space(observation_space), **base_kwargs)
        size = observation_space[PRIVILEGED].shape
        if len(size) != 1:
            raise ValueError(f"the privileged part must be a vector, got shape {size}")
        super().__init__(observation_space, base.features_dim)
        self.base = base
        self.inject = torch.nn.Linear(int(size[0]), base.features_dim)

    def forward(self, observations: dict) -> torch.Tensor:
        return self.base(observations) + self.inject(observations[PRIVILEGED])


class PrivilegedCriticPolicy(MultiInputActorCriticPolicy):
    """An actor-critic whose actor reads the ``Dict`` observation without
    its privileged vector and whose critic, a network of its own, reads it
    too. Only the critic shapes the advantages; the actor played needs
    nothing privileged. Its keywords are ``MultiInputActorCriticPolicy``'s
    (``share_features_extractor`` must stay False)."""

    def make_features_extractor(self) -> BaseFeaturesExtractor:
        return self.features_extractor_class(public_space(self.observation_space),
                                             **self.features_extractor_kwargs)

    def _build(self, lr_schedule) -> None:
        if self.share_features_extractor:
            raise ValueError("a privileged critic needs features of its own "
                             "(share_features_extractor=False)")
        self.vf_features_extractor = PrivilegedFeatures(
            self.observation_space, self.features_extractor_class,
            self.features_extractor_kwargs)
        super()._build(lr_schedule)
