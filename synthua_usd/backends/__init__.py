"""Backends: renderers and file writers. The only code that imports ``mitsuba`` or writes dataset files."""
