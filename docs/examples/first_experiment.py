import gymnasium as gym
import numpy as np
import iceenvs  # noqa: F401  (iceenvs registers the environments)
from stable_baselines3 import PPO
from agents.vec import GymnasiumVecEnv     # a Gymnasium vector environment as an SB3 VecEnv

def score(act, seeds=range(100, 110)):              # mean return of act(obs) -> action
    env, total = gym.make("iceenvs/Convergence-v0"), 0.0
    for seed in seeds:
        obs, _ = env.reset(seed=seed); done = False
        while not done:
            obs, r, term, trunc, _ = env.step(act(obs)); total += r; done = term or trunc
    return total / len(seeds)

envs = GymnasiumVecEnv(gym.make_vec("iceenvs/Convergence-v0", num_envs=2, vectorization_mode="vector_entry_point")); envs.seed(0)
model = PPO("MlpPolicy", envs, gamma=0.95, seed=0).learn(60_000)
best = max(np.linspace(-1, 1, 9), key=lambda a: score(lambda obs: [a], seeds=range(5)))
print(f"PPO {score(lambda obs: model.predict(obs, deterministic=True)[0]):.1f}, best constant rate {best:+.2f}: {score(lambda obs: [best]):.1f}")
