"""Agents: walkable graphs, profiles, populations and collision-free motion (plain data; no USD)."""
