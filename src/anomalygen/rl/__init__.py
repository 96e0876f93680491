"""Reinforcement learning: Gymnasium envs for sub-tasks, SAC and CEM, rewards, the reward-code sandbox."""
