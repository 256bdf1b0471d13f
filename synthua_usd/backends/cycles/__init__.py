"""Blender Cycles, for side-by-side comparisons: an interchange export (:mod:`.interchange`), the script the
Cycles interpreter runs (:mod:`.blender_render`, which alone imports ``bpy``) and its runner (:mod:`.runner`).
Cycles lives in a virtual environment of its own (``tools/setup_cycles.sh``), never in synthua's."""
