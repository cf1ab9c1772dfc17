"""Gymnasium environments for sea-ice control over floe physics.

Importing the package registers the environments:

=====================================  =========================================
id                                     task
=====================================  =========================================
``iceenvs/WindDrift-v0``               move ice along a heading with the wind
``iceenvs/Convergence-v0``             compress ice to a target concentration
``iceenvs/MarginalIceZone-v0``         transport ice along a fast-ice edge
``iceenvs/FloeClustering-v0``          herd hard-disc floes into clusters
``iceenvs/ThicknessDistribution-v0``   steer the ice thickness distribution
=====================================  =========================================

>>> import gymnasium as gym
>>> import iceenvs  # noqa: F401  (registers the ids)
>>> env = gym.make("iceenvs/WindDrift-v0")
"""
from gymnasium.envs.registration import register

__all__ = ["ENV_IDS"]

# Episodes are truncated by the environments themselves (argument
# ``episode_steps``, or ``episode_days`` for the ITD), so that changing the
# control interval or the episode length through ``gymnasium.make`` kwargs
# stays consistent; no TimeLimit wrapper is added.
_ENVS = {
    "WindDrift-v0": "iceenvs.wind_drift:WindDriftEnv",
    "Convergence-v0": "iceenvs.convergence:ConvergenceEnv",
    "MarginalIceZone-v0": "iceenvs.marginal_ice_zone:MarginalIceZoneEnv",
    "FloeClustering-v0": "iceenvs.floe_clustering:FloeClusteringEnv",
    "ThicknessDistribution-v0": "iceenvs.thickness_distribution:ThicknessDistributionEnv",
}

#: every registered id
ENV_IDS = tuple(f"iceenvs/{name}" for name in _ENVS)

for _name, _entry in _ENVS.items():
    register(id=f"iceenvs/{_name}", entry_point=_entry)
