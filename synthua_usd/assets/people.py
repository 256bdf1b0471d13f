"""How a person looks: which bank body (:mod:`synthua_usd.assets.bodies`), skin tone and clothes.

Bodies come from the body bank, whose phenotypes are sampled from stated population distributions
(:mod:`synthua_usd.assets.body_bank`); users of mobility aids draw from its older stratum. Skin tones are the
ten Monk Skin Tone swatches, drawn uniformly so every tone appears; clothes are an upper garment (short or
long sleeves), a lower garment (trousers or shorts/skirt length) and shoes, each a palette colour.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from synthua_usd.assets.bodies import load_bank
from synthua_usd.model.materials import SHIRTS, SHOES, SKINS, TROUSERS


@dataclass(frozen=True)
class PersonLook:
    """``body`` index into the body bank; material keys of skin, upper and lower garment and shoes;
    ``long_sleeves`` and ``long_legs`` say whether forearms and shins are clothed."""

    body: int
    skin: str
    shirt: str
    trousers: str
    shoes: str = "Shoes0"
    long_sleeves: bool = True
    long_legs: bool = True

    @classmethod
    def random(cls, rng: np.random.Generator, aid_user: bool = False, min_height_m: float = 0.0,
               long_sleeves: float = 0.6, long_legs: float = 0.6) -> "PersonLook":
        """A body uniform over the bank's general population (``aid_user``: over its older stratum) at least
        ``min_height_m`` tall, a skin tone uniform over the Monk scale, garment colours uniform over their
        palettes, long sleeves and long legs with probabilities ``long_sleeves`` and ``long_legs``."""
        bank = load_bank()
        pool = np.flatnonzero((bank.aid_stratum if aid_user else ~bank.aid_stratum) & (bank.height_m >= min_height_m))
        return cls(body=int(pool[int(rng.integers(len(pool)))]), skin=SKINS[int(rng.integers(len(SKINS)))].key,
                   shirt=SHIRTS[int(rng.integers(len(SHIRTS)))].key, trousers=TROUSERS[int(rng.integers(len(TROUSERS)))].key,
                   shoes=SHOES[int(rng.integers(len(SHOES)))].key, long_sleeves=bool(rng.random() < long_sleeves),
                   long_legs=bool(rng.random() < long_legs))

    def region_material(self, region: str) -> str:
        """The material key of a garment region of :data:`synthua_usd.assets.bodies.REGIONS`."""
        return {"skin": self.skin, "upper": self.shirt, "forearm": self.shirt if self.long_sleeves else self.skin,
                "lower": self.trousers, "shin": self.trousers if self.long_legs else self.skin, "shoes": self.shoes}[region]

    def materials(self) -> set[str]:
        return {self.region_material(r) for r in ("skin", "upper", "forearm", "lower", "shin", "shoes")}
