"""Computations on the twin, the agents and the cameras: projection to pixels, automatic framing, camera
placement, roads, texture coordinates, free space and the generated ground (plain data in, plain data out)."""
