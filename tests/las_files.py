"""Writing small LAS files for importer tests, with their CRS as GeoTIFF keys or WKT."""

import numpy as np


def write_las(path, xyz, classes=None, crs="EPSG:32633", geokeys=None, wkt=False):
    """A LAS 1.2 file of ``xyz`` (file units); its CRS as GeoTIFF keys (``crs`` by EPSG code through laspy,
    or ``geokeys``: key id -> value, written as given), or as a WKT record (LAS 1.4, ``wkt=True``); none
    with ``crs=None``."""
    import laspy
    from laspy.vlrs.known import GeoKeyDirectoryVlr, GeoKeyEntryStruct
    from pyproj import CRS

    header = laspy.LasHeader(point_format=6 if wkt else 3, version="1.4" if wkt else "1.2")
    header.scales = np.array([0.001, 0.001, 0.001])
    header.offsets = xyz.min(axis=0) if len(xyz) else np.zeros(3)
    if geokeys is not None:
        vlr = GeoKeyDirectoryVlr()
        vlr.geo_keys = [GeoKeyEntryStruct(k, 0, 1, v) for k, v in geokeys.items()]
        vlr.geo_keys_header.number_of_keys = len(vlr.geo_keys)
        header.vlrs.append(vlr)
    elif crs is not None:
        header.add_crs(CRS.from_user_input(crs))
    las = laspy.LasData(header)
    las.x, las.y, las.z = xyz[:, 0], xyz[:, 1], xyz[:, 2]
    if classes is not None:
        las.classification = classes
    las.write(str(path))
    return path
