"""What a scenario composes: the scenario itself (twin, crowd, cameras, conditions, render settings) and the
camera rig types. Above :mod:`synthua_usd.agents`: a scenario holds a crowd, and rigs aim at aid users."""
