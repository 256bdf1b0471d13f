"""Coordinate reference systems: the linear units of a file's coordinates (CRS, GeoTIFF keys or the user's
``--crs``/``--units``), checking that a CRS is metric, and projecting lon/lat to local metres."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from synthua_usd.core.errors import InputError, echo


def require_projected_metres(crs_text: str, source: str):
    """The pyproj CRS for ``crs_text``; refuse geographic (degree) or non-metre systems."""
    from pyproj import CRS
    from pyproj.exceptions import CRSError

    try:
        crs = CRS.from_user_input(_normalise(crs_text))
    except CRSError as exc:
        raise InputError(f"{source}: unknown CRS '{echo(crs_text)}' ({echo(exc)}); expected an EPSG code or CRS URL of "
                         f"a projected CRS in metres") from None
    horizontal = crs.sub_crs_list[0] if crs.is_compound else crs
    if not horizontal.is_projected:
        raise InputError(f"{source}: CRS '{echo(crs_text)}' is geographic (degrees); expected a projected CRS in metres "
                         f"(reproject the file first)")
    units = {a.unit_name for a in horizontal.axis_info}
    if units - {"metre", "meter"}:
        raise InputError(f"{source}: CRS '{echo(crs_text)}' uses units {sorted(units)}; expected metres")
    return crs


def _normalise(text: str) -> str:
    # CityJSON writes "https://www.opengis.net/def/crs/EPSG/0/7415"; GeoJSON (2008) "urn:ogc:def:crs:EPSG::28992".
    for marker in ("/EPSG/0/", "EPSG::"):
        if marker in text:
            return "EPSG:" + text.rsplit(marker, 1)[1].strip("/")
    return text


def local_tmerc(lonlat: np.ndarray) -> str:
    """PROJ string of a transverse Mercator (metres) centred on the mean of (n, 2) WGS84 lon/lat degrees."""
    lon0, lat0 = (float(v) for v in np.asarray(lonlat, float).mean(axis=0))
    return f"+proj=tmerc +lat_0={lat0:.9f} +lon_0={lon0:.9f} +k=1 +x_0=0 +y_0=0 +ellps=WGS84 +units=m +no_defs"


def lonlat_to(proj: str, lonlat: np.ndarray) -> np.ndarray:
    """(n, 2) WGS84 lon/lat degrees → (n, 2) metres in the CRS ``proj``."""
    from pyproj import Transformer

    x, y = Transformer.from_crs("EPSG:4326", proj, always_xy=True).transform(lonlat[:, 0], lonlat[:, 1])
    return np.column_stack([x, y])


# --- linear units -------------------------------------------------------------------------------------------

#: ``--units`` names → (unit name, metres per unit). US survey foot: 1200/3937 m (exact by definition).
UNIT_CHOICES = {"m": ("metre", 1.0), "ft": ("foot", 0.3048), "us-ft": ("US survey foot", 1200 / 3937)}

#: GeoTIFF keys (GeoTIFF 1.0, section 6.2) read for units: model type, projected CRS code, its linear unit,
#: vertical CRS code and vertical unit. 32767 means "user-defined" (no EPSG code).
GT_MODEL_TYPE, PROJECTED_CRS, PROJ_LINEAR_UNITS, VERTICAL_CRS, VERTICAL_UNITS = 1024, 3072, 3076, 4096, 4099
USER_DEFINED = 32767


@dataclass(frozen=True)
class LinearUnits:
    """The linear units of a file's coordinates: metres per unit horizontally (x, y) and vertically (z),
    their names, and where they were learnt (``source``: 'WKT', 'GeoTIFF keys', 'CRS', '--crs', '--units').
    ``vertical_assumed`` is True when nothing stated the vertical unit and the horizontal one was taken."""

    horizontal_m: float
    vertical_m: float
    horizontal_name: str
    vertical_name: str
    source: str
    vertical_assumed: bool = False

    @property
    def scale(self) -> np.ndarray:
        """(3,) float64 metres per unit for x, y, z."""
        return np.array([self.horizontal_m, self.horizontal_m, self.vertical_m])

    def as_report(self) -> dict:
        return {"horizontal": self.horizontal_name, "horizontal_m_per_unit": self.horizontal_m,
                "vertical": self.vertical_name, "vertical_m_per_unit": self.vertical_m,
                "vertical_assumed_from_horizontal": self.vertical_assumed, "source": self.source}


def parse_crs(text: str, source: str):
    """The pyproj CRS of ``text``: an EPSG code ('EPSG:2263', '2263'), a CRS URL/URN, WKT or a PROJ string."""
    from pyproj import CRS
    from pyproj.exceptions import CRSError

    text = text.strip()
    try:
        return CRS.from_user_input(f"EPSG:{text}" if text.isdigit() else _normalise(text))
    except CRSError as exc:
        raise InputError(f"{source}: unknown CRS '{echo(text[:120])}' ({echo(str(exc)[:160])}); expected an EPSG code "
                         f"(EPSG:2263), a CRS URL or WKT") from None


def crs_units(crs, source: str, where: str) -> LinearUnits:
    """The linear units of a pyproj CRS; refuses geographic (degree) systems. A CRS without a vertical axis
    leaves z in the horizontal unit (stated: ``vertical_assumed``)."""
    horizontal = crs.sub_crs_list[0] if crs.is_compound else crs
    if not horizontal.is_projected:
        kind = "geographic (degrees)" if horizontal.is_geographic else "not projected"
        raise InputError(f"{where}: CRS '{echo(crs.name)}' is {kind}; "
                         f"expected a projected CRS (reproject the file first, or give --crs)")
    h_axis = horizontal.axis_info[0]
    vertical_axes = [a for a in crs.axis_info if a.direction in ("up", "down")]
    if vertical_axes:
        v = vertical_axes[0]
        return LinearUnits(h_axis.unit_conversion_factor, v.unit_conversion_factor, h_axis.unit_name, v.unit_name,
                           source)
    return LinearUnits(h_axis.unit_conversion_factor, h_axis.unit_conversion_factor, h_axis.unit_name,
                       h_axis.unit_name, source, vertical_assumed=True)


def _unit_by_code(code: int) -> tuple[str, float] | None:
    from pyproj.database import get_units_map

    for name, unit in get_units_map(category="linear").items():
        if unit.code == str(code) and unit.auth_name == "EPSG":
            return name, float(unit.conv_factor)
    return None


def _key_unit(keys: dict[int, int], unit_key: int, crs_key: int) -> tuple[str, float] | None:
    """(name, metres) of the unit key's EPSG unit code, else of the first axis of the CRS key's EPSG CRS."""
    from pyproj import CRS
    from pyproj.exceptions import CRSError

    if keys.get(unit_key, USER_DEFINED) != USER_DEFINED:
        found = _unit_by_code(keys[unit_key])
        if found is not None:
            return found
    if keys.get(crs_key, USER_DEFINED) != USER_DEFINED:
        try:
            axis = CRS.from_epsg(keys[crs_key]).axis_info[0]
        except CRSError:
            return None
        return axis.unit_name, axis.unit_conversion_factor
    return None


def geotiff_units(keys: dict[int, int], where: str) -> LinearUnits | None:
    """Linear units from GeoTIFF keys (key id → short value; LAS GeoKeyDirectory VLR): the projected linear
    unit key, else the projected CRS's EPSG code; the vertical unit key, else the vertical CRS's code, else the
    horizontal unit. None when the keys name no horizontal unit."""
    if keys.get(GT_MODEL_TYPE) == 2:
        raise InputError(f"{where}: the GeoTIFF keys describe a geographic CRS (degrees); expected a projected CRS "
                         f"(reproject the file first, or give --crs)")
    horizontal = _key_unit(keys, PROJ_LINEAR_UNITS, PROJECTED_CRS)
    if horizontal is None:
        return None
    vertical = _key_unit(keys, VERTICAL_UNITS, VERTICAL_CRS)
    return LinearUnits(horizontal[1], (vertical or horizontal)[1], horizontal[0], (vertical or horizontal)[0],
                       "GeoTIFF keys", vertical_assumed=vertical is None)


def resolve_units(found: LinearUnits | None, user_crs: str | None, user_units: str | None, where: str,
                  what: str = "the file has no CRS") -> LinearUnits:
    """The units to convert with: ``--crs`` first, then ``--units``, then what the file says; refuses when
    none is known (one line naming the options)."""
    if user_crs:
        return crs_units(parse_crs(user_crs, "--crs"), "--crs", "--crs")
    if user_units:
        if user_units not in UNIT_CHOICES:
            raise InputError(f"--units: '{echo(user_units)}'; expected one of {', '.join(UNIT_CHOICES)}")
        name, factor = UNIT_CHOICES[user_units]
        return LinearUnits(factor, factor, name, name, "--units")
    if found is None:
        raise InputError(f"{where}: the unit of the coordinates cannot be determined ({what}); expected a CRS in the "
                         f"file, or --crs EPSG:CODE|WKT, or --units {'|'.join(UNIT_CHOICES)}")
    return found
