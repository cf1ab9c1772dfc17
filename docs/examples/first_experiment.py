import gymnasium as gym
import numpy as np
import iceenvs  # noqa: F401  (iceenvs registers the environments)
from stable_baselines3 import PPO
from stable_baselines3.common.env_util import make_vec_env

def score(act, seeds=range(100, 110)):              # mean return of act(obs) -> action
    env, total = gym.make("iceenvs/Convergence-v0"), 0.0
    for seed in seeds:
        obs, _ = env.reset(seed=seed); done = False
        while not done:
            obs, r, term, trunc, _ = env.step(act(obs)); total += r; done = term or trunc
    return total / len(seeds)

model = PPO("MlpPolicy", make_vec_env("iceenvs/Convergence-v0", n_envs=2, seed=0), gamma=0.95, seed=0).learn(60_000)
best = max(np.linspace(-1, 1, 9), key=lambda a: score(lambda obs: [a], seeds=range(5)))
print(f"PPO {score(lambda obs: model.predict(obs, deterministic=True)[0]):.1f}, best constant rate {best:+.2f}: {score(lambda obs: [best]):.1f}")
