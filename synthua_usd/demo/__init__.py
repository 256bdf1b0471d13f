"""The demo scenarios as library code: the demo street and the Largo da Ordem district, and their textures."""
