"""Plain scene data, free of USD and of any renderer: meshes, the twin, materials, lamps, cameras and lens
distortion, conditions, render settings, the taxonomy and class map, keypoint classes, units and ranges."""
