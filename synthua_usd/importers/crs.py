"""Coordinate reference systems: checking that a CRS is metric and projecting lon/lat to local metres."""

from __future__ import annotations

import numpy as np

from synthua_usd.errors import InputError, echo


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
