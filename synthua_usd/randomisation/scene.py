"""One randomised scene as plain data: who is in the crowd and how they look (hair too), each aid user's
device, each twin object's material variant, and the district seed.

A scene is shared by the images of one seed (:mod:`synthua_usd.randomisation.streams`): a worker loads it
once and every (camera, time code) then places its crowd anew (:mod:`synthua_usd.randomisation.view`). Every
choice is recorded (:meth:`SceneDraw.to_dict`) so a record names it; the USD side authors it
(:mod:`synthua_usd.usd.randomisation_layer`).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, replace

import numpy as np

from synthua_usd.agents.profiles import PROFILES
from synthua_usd.agents.seats import SeatPlace
from synthua_usd.assets.bodies import load_bank
from synthua_usd.assets.devices import DEVICE_MODELS
from synthua_usd.assets.hair import HAIR_STYLES
from synthua_usd.assets.people import PersonLook
from synthua_usd.assets.postures import DeviceFit, fit_device
from synthua_usd.model.materials import (DEVICE_FINISHES, HAIR_COLOURS, PALETTE, RECOLOUR_PALETTES, SEAT_FABRICS, SHIRTS, SHOES, TROUSERS,
                                   WOOD_COLOURS)
from synthua_usd.randomisation.config import LooksRandomisation, RandomisationConfig
from synthua_usd.randomisation.wear import Wardrobe, Wear, draw_wardrobe, draw_wear, jitter, pick

RGB = tuple[float, float, float]
#: Most people one randomised scene holds (a bound on the layers and the render, whatever the walkable area).
MAX_CAST = 2000
#: Group sizes of pedestrians walking together.
GROUP_SIZES = (2, 3)
#: How many companions walk beside an accompanied aid user.
COMPANIONS = (1, 2)
#: Shortest companion who pushes a wheelchair, m (the handles are about 0.9-1.1 m high).
PUSHER_MIN_HEIGHT_M = 1.5
#: Weights of the hair styles (order of :data:`HAIR_STYLES`: none, short, medium, long) for women and men.
HAIR_STYLE_WEIGHTS = {True: (0.03, 0.2, 0.35, 0.42), False: (0.2, 0.55, 0.2, 0.05)}
#: Weights of the hair colours other than grey (keys of :data:`HAIR_COLOURS`); grey is drawn with probability
#: (years - 45) / 40, within [0, 0.85].
HAIR_COLOUR_WEIGHTS = {"black": 0.3, "dark_brown": 0.35, "brown": 0.18, "light_brown": 0.07, "blonde": 0.06,
                       "auburn": 0.04}
#: The profile of each aid class.
PROFILE_OF_AID = {p.device: p.name for p in PROFILES.values() if p.device is not None}


@dataclass(frozen=True)
class Finish:
    """A device part's surface: linear Rec.709 base colour, roughness, metallic; ``name`` the finish or fabric."""

    name: str
    base_color: RGB
    roughness: float
    metallic: float


@dataclass(frozen=True)
class DeviceLook:
    """An aid user's device: its ``model`` (a key of :data:`synthua_usd.assets.devices.DEVICE_MODELS` for its
    class), the finish of its frame (wood for a wooden cane) and the fabric of its seat."""

    model: str
    frame: Finish
    seat: Finish


@dataclass(frozen=True)
class HairLook:
    """A person's hair: ``style`` one of :data:`synthua_usd.assets.hair.HAIR_STYLES`, and (None when bald) its
    colour's name (a key of :data:`synthua_usd.model.materials.HAIR_COLOURS`), linear Rec.709 base colour and
    roughness."""

    style: str
    colour: str | None = None
    base_color: RGB | None = None
    roughness: float | None = None


@dataclass(frozen=True)
class CastMember:
    """One person of the scene: profile (a key of :data:`synthua_usd.agents.profiles.PROFILES`), body index into
    the body bank, skin tone (a Monk swatch's palette key), garment colours, sleeve and leg length, the device
    of an aid user, the bench place of a sitter (kept for the whole scene), the group of people walking
    together, the hair (None: not randomised, bald) and the wear (fabrics, shoes; None: the looks are not
    randomised, flat colours). A companion of an aid user has the aid user's index in
    the cast in ``pushes`` (it walks behind a manual wheelchair, hands on its push handles, ``pushing`` that
    chair's fit) or in ``accompanies`` (it walks beside); the pushed user has its pusher's in ``pushed_by``."""

    profile: str
    body: int
    skin: str
    upper: RGB
    lower: RGB
    shoes: RGB
    long_sleeves: bool
    long_legs: bool
    device: DeviceLook | None = None
    seat: SeatPlace | None = None
    group: int | None = None
    hair: HairLook | None = None
    pushes: int | None = None
    pushing: DeviceFit | None = None
    pushed_by: int | None = None
    accompanies: int | None = None
    wear: Wear | None = None

    @property
    def aid(self) -> str | None:
        return PROFILES[self.profile].device

    def region_colour(self, region: str) -> RGB | str:
        """The colour of a garment region of :data:`synthua_usd.assets.bodies.REGIONS`, or the skin's palette key
        where the region shows skin."""
        return {"skin": self.skin, "upper": self.upper, "forearm": self.upper if self.long_sleeves else self.skin,
                "lower": self.lower, "shin": self.lower if self.long_legs else self.skin, "shoes": self.shoes}[region]


@dataclass(frozen=True)
class Recolour:
    """One twin object's variant of its main material: ``material`` the bound material's key (its prim path),
    and either a new constant ``base_color`` or a ``tint`` multiplying its colour or texture (RGB)."""

    prim_path: str
    class_name: str
    material: str
    base_color: RGB | None = None
    tint: RGB | None = None


@dataclass(frozen=True)
class Recolourable:
    """What the twin offers for recolouring: a labelled object, its class, the key of the material that covers
    most of it, whether that material is textured, and its base colour."""

    prim_path: str
    class_name: str
    material: str
    textured: bool
    base_color: RGB


@dataclass(frozen=True)
class SceneDraw:
    """Everything one scene drew. ``cast`` empty and ``density_per_m2`` None when the crowd is not randomised;
    ``wardrobe`` None without looks."""

    scene_seed: int
    district_seed: int | None
    density_per_m2: float | None
    aid_share: float | None
    cast: tuple[CastMember, ...]
    recolours: tuple[Recolour, ...]
    wardrobe: Wardrobe | None = None

    def to_dict(self) -> dict:
        return asdict(self)


def _device_look(rng: np.random.Generator, aid: str, config: RandomisationConfig) -> DeviceLook:
    """The model (uniform over the class's models that ``devices.models`` allows, drawn from a child stream of
    ``rng``: ``rng`` itself draws as many numbers whatever the number of models, so adding a model, or allowing
    fewer, changes no other draw of the scene), then the finishes."""
    model = pick(rng.spawn(1)[0], [m for m in sorted(DEVICE_MODELS[aid]) if m in config.devices.models])
    if not config.devices.enabled:
        base = PALETTE["Frame"]
        seat = PALETTE["Seat"]
        return DeviceLook(model, Finish("standard", base.base_color, base.roughness, base.metallic),
                          Finish("standard", seat.base_color, seat.roughness, seat.metallic))
    if aid == "wooden_cane":
        frame = Finish("wood", jitter(rng, pick(rng, WOOD_COLOURS), 0.15), 0.6, 0.0)
    else:
        name = pick(rng, config.devices.finishes)
        palette, roughness, metallic = DEVICE_FINISHES[name]
        frame = Finish(name, jitter(rng, pick(rng, palette), 0.1), roughness, metallic)
    seat = Finish("fabric", jitter(rng, pick(rng, SEAT_FABRICS), 0.2), 0.9, 0.0)
    return DeviceLook(model, frame, seat)


def _weighted(u: float, names, weights: dict) -> str:
    """The name of ``names`` at ``u`` in [0, 1) of their ``weights``' cumulative distribution."""
    w = np.array([weights[n] for n in names], float)
    return names[min(int(np.searchsorted(np.cumsum(w / w.sum()), u, side="right")), len(names) - 1)]


def draw_hair(rng: np.random.Generator, body: int, config: RandomisationConfig) -> HairLook:
    """A style among the config's (weighted by the body's sex, :data:`HAIR_STYLE_WEIGHTS`) and a colour among
    the config's: grey with a probability rising with the body's age, else by :data:`HAIR_COLOUR_WEIGHTS`,
    each channel scaled by 1 + U(-0.1, 0.1). Always five numbers of ``rng``, whatever is drawn."""
    bank = load_bank()
    hair = config.hair
    u_style, u_grey, u_colour = rng.random(3)
    scale = 1.0 + rng.uniform(-0.1, 0.1, 2)
    weights = dict(zip(HAIR_STYLES, HAIR_STYLE_WEIGHTS[bool(bank.female[body])]))
    style = _weighted(float(u_style), hair.styles, weights)
    if style == "none":
        return HairLook(style)
    coloured = tuple(c for c in hair.colours if c != "grey")
    grey = float(np.clip((float(bank.years[body]) - 45.0) / 40.0, 0.0, 0.85)) if "grey" in hair.colours else 0.0
    name = "grey" if not coloured or u_grey < grey else _weighted(float(u_colour), coloured, HAIR_COLOUR_WEIGHTS)
    rgb, roughness = HAIR_COLOURS[name]
    value, hue = scale  # brightness, and a warmer or cooler shift of red against blue
    colour = np.clip(np.asarray(rgb, float) * value * np.array([hue, 1.0, 2.0 - hue]), 0.0, 1.0)
    return HairLook(style, name, tuple(float(c) for c in colour), roughness)


#: Whose sleeve and leg lengths a person draws while looks are off: the defaults, as before the fields existed.
LOOKS_OFF = LooksRandomisation()


def _member(rng: np.random.Generator, profile: str, config: RandomisationConfig, seat=None,
            group=None, min_height_m: float = 0.0) -> CastMember:
    aid = PROFILES[profile].device
    looks = config.looks if config.looks.enabled else LOOKS_OFF
    look = PersonLook.random(rng, aid_user=aid is not None, min_height_m=min_height_m,
                             long_sleeves=looks.long_sleeves, long_legs=looks.long_legs)
    amount = config.crowd.clothing_jitter
    colour = {"Shirt": SHIRTS, "Trousers": TROUSERS, "Shoes": SHOES}
    upper, lower, shoes = (jitter(rng, pick(rng, colour[kind]).base_color, amount) for kind in colour)
    device = _device_look(rng, aid, config) if aid is not None else None
    return CastMember(profile=profile, body=look.body, skin=look.skin, upper=upper, lower=lower, shoes=shoes,
                      long_sleeves=look.long_sleeves, long_legs=look.long_legs, device=device, seat=seat, group=group)


def _companions(rng: np.random.Generator, config: RandomisationConfig, members: list[CastMember], room: int,
                pushed_share: float, accompanied_share: float, group: int) -> bool:
    """Maybe add companions to the aid user last in ``members`` (at most ``room`` people), drawing from ``rng``
    (the scene's companion stream): a manual wheelchair's user is pushed with probability ``pushed_share`` (a
    pusher at least :data:`PUSHER_MIN_HEIGHT_M` tall), any other aid user (and a chair user not pushed) walks
    with 1-2 companions with probability ``accompanied_share``. The user and its companions take ``group``;
    True when any were added. Always the same numbers of ``rng`` drawn for the decisions, whatever is added."""
    k = len(members) - 1
    user = members[k]
    push, accompany, many = rng.random(3)
    if user.aid == "manual_wheelchair" and push < pushed_share and room >= 1:
        chair = fit_device(load_bank(), user.body, "manual_wheelchair")
        pusher = replace(_member(rng, "pedestrian", config, group=group, min_height_m=PUSHER_MIN_HEIGHT_M),
                         pushes=k, pushing=chair)
        members[k] = replace(user, group=group, pushed_by=k + 1)
        members.append(pusher)
        return True
    if accompany < accompanied_share and room >= 1:
        size = min(COMPANIONS[int(many * len(COMPANIONS))], room)
        members[k] = replace(user, group=group)
        members += [replace(_member(rng, "pedestrian", config, group=group), accompanies=k) for _ in range(size)]
        return True
    return False


def draw_cast(rng: np.random.Generator, config: RandomisationConfig, walkable_area_m2: float,
              seats: list[SeatPlace]) -> tuple[float, float, tuple[CastMember, ...], Wardrobe | None]:
    """(density, aid share, members, wardrobe): N ~ Poisson(density x ``walkable_area_m2``) people (at most
    :data:`MAX_CAST`), each an aid user with probability ``aid share`` (the aid uniform over the config's
    aids; then maybe pushed or accompanied by companions among the N, :func:`_companions`, drawn from a child
    stream of ``rng``), else a pedestrian who sits on a free bench place of ``seats`` with probability
    ``seated_share`` or walks in a group of 2-3 with probability ``group_share``; then, with hair on, each
    member's hair (:func:`draw_hair`), and with looks on the scene's wardrobe and each member's pick from it
    (:mod:`synthua_usd.randomisation.wear`; None without looks), each from a child stream of ``rng``."""
    crowd = config.crowd
    density = float(rng.uniform(*crowd.density_per_m2))
    aid_share = float(rng.uniform(*crowd.aid_share))
    seated_share = float(rng.uniform(*crowd.seated_share))
    group_share = float(rng.uniform(*crowd.group_share))
    count = min(MAX_CAST, int(rng.poisson(density * walkable_area_m2)))
    free = list(range(len(seats)))
    members: list[CastMember] = []
    groups = 0
    # the companions' own stream, spawned after the devices' (spawning draws nothing from rng)
    companion_rng = rng.spawn(1)[0]
    pushed_share = float(companion_rng.uniform(*crowd.pushed_share))
    accompanied_share = float(companion_rng.uniform(*crowd.accompanied_share))
    while len(members) < count:
        if rng.random() < aid_share:
            members.append(_member(rng, PROFILE_OF_AID[pick(rng, crowd.aids)], config))
            if _companions(companion_rng, config, members, count - len(members), pushed_share, accompanied_share,
                           groups):
                groups += 1
        elif free and rng.random() < seated_share:
            members.append(_member(rng, "pedestrian", config, seat=seats[free.pop(int(rng.integers(len(free))))]))
        elif rng.random() < group_share and count - len(members) >= 2:
            size = min(int(pick(rng, GROUP_SIZES)), count - len(members))
            members += [_member(rng, "pedestrian", config, group=groups) for _ in range(size)]
            groups += 1
        else:
            members.append(_member(rng, "pedestrian", config))
    members, wardrobe = _styled(rng, config, members)
    return density, aid_share, members, wardrobe


def _styled(rng: np.random.Generator, config: RandomisationConfig,
            members: list[CastMember]) -> tuple[tuple[CastMember, ...], Wardrobe | None]:
    """``members`` with their hair (hair on) and their wear from a wardrobe drawn here (looks on; None without),
    from one child stream of ``rng`` each, spawned whether or not they are used: no other draw moves."""
    hair_rng, wear_rng = rng.spawn(2)
    if config.hair.enabled:
        members = [replace(m, hair=draw_hair(hair_rng, m.body, config)) for m in members]
    wardrobe = None
    if config.looks.enabled:  # people dress from the scene's wardrobe: its garments' colours replace their own
        wardrobe = draw_wardrobe(wear_rng, config.looks, config.crowd.clothing_jitter)
        members = [dressed(m, draw_wear(wear_rng, wardrobe), wardrobe) for m in members]
    return tuple(members), wardrobe


#: How an aid user of a cut-out comes: on its own, pushed by a companion (manual wheelchairs), or with 1-2
#: companions walking beside it.
UNIT_GROUPS = ("alone", "pushed", "accompanied")


def draw_unit(rng: np.random.Generator, config: RandomisationConfig, aid: str | None,
              group: str = "alone") -> tuple[tuple[CastMember, ...], Wardrobe | None]:
    """The cast of one cut-out: a pedestrian (``aid`` None), or a user of ``aid`` (a class of
    :data:`AID_CLASSES`) ``group`` (:data:`UNIT_GROUPS`; ``pushed`` only for a manual wheelchair), its companions
    after it; each person drawn as a crowd's is (body, skin, clothes, device look, hair, wear)."""
    if group not in UNIT_GROUPS or (aid is None and group != "alone") or (group == "pushed" and aid != "manual_wheelchair"):
        raise ValueError(f"a cut-out of a {aid or 'pedestrian'} {group}: no such unit; expected a pedestrian alone, "
                         f"any aid user alone or accompanied, or a manual wheelchair user pushed")
    members = [_member(rng, "pedestrian" if aid is None else PROFILE_OF_AID[aid], config)]
    if group != "alone":
        _companions(rng.spawn(1)[0], config, members, 2, 1.0 if group == "pushed" else 0.0,
                    1.0 if group == "accompanied" else 0.0, 0)
    return _styled(rng, config, members)


def dressed(member: CastMember, wear: Wear, wardrobe: Wardrobe) -> CastMember:
    """``member`` wearing ``wear`` from ``wardrobe``: its garment and shoe colours those of what it picked."""
    return replace(member, upper=wardrobe.uppers[wear.upper].colour, lower=wardrobe.lowers[wear.lower].colour,
                   shoes=wardrobe.shoes[wear.shoes].colour, wear=wear)


def draw_recolours(rng: np.random.Generator, config: RandomisationConfig,
                   objects: list[Recolourable]) -> tuple[Recolour, ...]:
    """A material variant for each of ``objects`` whose class the config recolours (in prim-path order): a
    colour of its class's palette (for a textured material, its texture tinted towards that colour), or a
    tint of its own colour for ground classes; brightness scaled by 1 ± ``value_jitter``."""
    materials = config.materials
    out = []
    for obj in sorted(objects, key=lambda o: o.prim_path):
        if obj.class_name not in materials.classes or obj.class_name not in RECOLOUR_PALETTES:
            continue
        kind, palette = RECOLOUR_PALETTES[obj.class_name]
        value = 1.0 + float(rng.uniform(-materials.value_jitter, materials.value_jitter))
        chosen = np.asarray(pick(rng, palette), float)
        if kind == "tint":
            out.append(Recolour(obj.prim_path, obj.class_name, obj.material, tint=tuple(float(v) for v in chosen * value)))
        elif obj.textured:
            # the texture's detail kept, its mean colour moved towards the palette colour
            own = np.maximum(np.asarray(obj.base_color, float), 1e-3)
            tint = np.clip(chosen / own, 0.2, 5.0) * value
            out.append(Recolour(obj.prim_path, obj.class_name, obj.material, tint=tuple(float(v) for v in tint)))
        else:
            colour = np.clip(chosen * value, 0.0, 1.0)
            out.append(Recolour(obj.prim_path, obj.class_name, obj.material, base_color=tuple(float(v) for v in colour)))
    return tuple(out)


def draw_scene(rng: np.random.Generator, config: RandomisationConfig, scene_seed: int, *, walkable_area_m2: float,
               seats: list[SeatPlace], objects: list[Recolourable], district_seed: int | None) -> SceneDraw:
    """The scene of ``scene_seed``: its cast (when the crowd is randomised) then its recolours (when materials
    are), drawn from ``rng`` in that order."""
    density = aid_share = None
    cast: tuple[CastMember, ...] = ()
    wardrobe = None
    if config.crowd.enabled:
        density, aid_share, cast, wardrobe = draw_cast(rng, config, walkable_area_m2, seats)
    recolours = draw_recolours(rng, config, objects) if config.materials.enabled else ()
    return SceneDraw(scene_seed=scene_seed, district_seed=district_seed, density_per_m2=density, aid_share=aid_share,
                     cast=cast, recolours=recolours, wardrobe=wardrobe)
