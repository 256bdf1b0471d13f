"""Agent profiles: how fast people move and what they can traverse, per mobility aid.

Speeds are means and spreads in m/s, approximate values from the literature (see docs/agents.md):
pedestrians after Bosina & Weidmann (2017, mean free walking speed 1.34 m/s); users of assistive
devices walk markedly slower (Fitzpatrick, Brewer & Turner 2006; Knoblauch et al. 1996); manual
wheelchair users after Tolerico et al. (2007) and Sonenblum et al. (2012); powered chairs are
governed to about 6 km/h. They are defaults to override, not measurements of ours.
"""

from __future__ import annotations

from dataclasses import dataclass

from synthua_usd.core.errors import InputError


@dataclass(frozen=True)
class AgentProfile:
    """What one kind of agent does.

    Attributes
    ----------
    name : str
    device : str | None
        Class name of the mobility aid (None for pedestrians).
    speed_mps, speed_sd_mps : float
        Mean and standard deviation of the preferred speed, m/s.
    radius_m : float
        Radius of the disc the agent occupies (person plus device), metres.
    can_step_kerb : bool
        Whether a kerb (a step of up to 20 cm) can be stepped up or down; if not, curb ramps only.
    max_slope : float
        Steepest running slope traversed (rise/run); 1:12 = 0.083 for wheelchairs.
    slope_penalty : float
        Extra cost per unit of slope above 2 %: time multiplier 1 + penalty * (slope - 0.02).
    cobble_factor : float
        Time multiplier on cobbled surfaces.
    seated : bool
        Sits in the device (wheelchairs).
    """

    name: str
    device: str | None
    speed_mps: float
    speed_sd_mps: float
    radius_m: float
    can_step_kerb: bool
    max_slope: float
    slope_penalty: float
    cobble_factor: float
    seated: bool = False

    def __post_init__(self) -> None:
        if not 0 < self.speed_mps < 3:
            raise InputError(f"profile {self.name}: speed_mps should be in (0, 3), but was {self.speed_mps}")
        if not 0.1 <= self.radius_m <= 1.0:
            raise InputError(f"profile {self.name}: radius_m should be in [0.1, 1.0], but was {self.radius_m}")


PROFILES: dict[str, AgentProfile] = {p.name: p for p in [
    AgentProfile("pedestrian", None, 1.34, 0.2, 0.25, True, 0.5, 2.0, 1.1),
    AgentProfile("manual_wheelchair", "manual_wheelchair", 1.0, 0.15, 0.45, False, 0.083, 12.0, 1.6, seated=True),
    AgentProfile("electric_wheelchair", "electric_wheelchair", 1.3, 0.15, 0.5, False, 0.1, 4.0, 1.3, seated=True),
    AgentProfile("walker", "walker", 0.6, 0.1, 0.4, False, 0.083, 10.0, 1.5),
    AgentProfile("crutches", "crutch", 0.8, 0.12, 0.35, True, 0.2, 6.0, 1.4),
    AgentProfile("smart_cane", "smart_cane", 1.0, 0.15, 0.3, True, 0.3, 3.0, 1.2),
    AgentProfile("wooden_cane", "wooden_cane", 0.9, 0.12, 0.3, True, 0.3, 4.0, 1.3),
    AgentProfile("orthopedic_cane", "orthopedic_cane", 0.85, 0.12, 0.3, True, 0.3, 4.0, 1.3),
    AgentProfile("tripod_cane", "tripod_cane", 0.7, 0.1, 0.32, True, 0.2, 6.0, 1.4),
]}

AID_PROFILES = tuple(p for p in PROFILES if PROFILES[p].device is not None)
