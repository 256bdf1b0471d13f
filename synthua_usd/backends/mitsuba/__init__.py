"""Mitsuba 3 backend: variant selection, scene translation, RGB and label rendering."""
