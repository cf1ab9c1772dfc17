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
``iceenvs/ShipNavigation-v0``          sail a ship through pack ice to a goal
``iceenvs/ShipBeset-v0``               keep a ship moving in pressured ice
``iceenvs/ShipNavigation-v1``          cross a kilometre of pack ice (AUTO-IceNav's fields)
=====================================  =========================================

>>> import gymnasium as gym
>>> import iceenvs  # noqa: F401  (registers the ids)
>>> env = gym.make("iceenvs/WindDrift-v0")
"""
from gymnasium.envs.registration import register

__all__ = ["ENV_IDS"]

# Every id is registered with its episode length: ``env.spec.max_episode_steps``
# is set, Gymnasium's TimeLimit truncates the episodes, and
# ``gymnasium.make(id, max_episode_steps=N)`` changes the length. The
# environments never truncate on their own. Every environment has a native
# vector environment (iceenvs.vector), named third: the class beside the
# environment's, and gymnasium.make_vec(id, num_envs=N,
# vectorization_mode="vector_entry_point") builds it.
_ENVS = {
    "WindDrift-v0": ("iceenvs.wind_drift:WindDriftEnv", 200, "WindDriftVectorEnv"),
    "Convergence-v0": ("iceenvs.convergence:ConvergenceEnv", 150, "ConvergenceVectorEnv"),
    "MarginalIceZone-v0": ("iceenvs.marginal_ice_zone:MarginalIceZoneEnv", 200,
                           "MarginalIceZoneVectorEnv"),
    "FloeClustering-v0": ("iceenvs.floe_clustering:FloeClusteringEnv", 400,
                          "FloeClusteringVectorEnv"),
    "ThicknessDistribution-v0": ("iceenvs.thickness_distribution:ThicknessDistributionEnv", 360,
                                 "ThicknessDistributionVectorEnv"),
    "ShipNavigation-v0": ("iceenvs.ship_navigation:ShipNavigationEnv", 300,
                          "ShipNavigationVectorEnv"),
    "ShipBeset-v0": ("iceenvs.ship_beset:ShipBesetEnv", 300, "ShipBesetVectorEnv"),
    "ShipNavigation-v1": ("iceenvs.ship_navigation_v1:ShipNavigationV1Env", 550,
                          "ShipNavigationV1VectorEnv"),
}

#: every registered id
ENV_IDS = tuple(f"iceenvs/{name}" for name in _ENVS)

for _name, (_entry, _steps, _vector) in _ENVS.items():
    register(id=f"iceenvs/{_name}", entry_point=_entry, max_episode_steps=_steps,
             vector_entry_point=_vector and f"{_entry.partition(':')[0]}:{_vector}")
