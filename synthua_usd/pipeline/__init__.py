"""Jobs that join the parts: read a stage (usd), render it (backends), write the outputs (backends)."""
