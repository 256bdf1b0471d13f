"""The floor every other package stands on: errors and their one-line messages, input files read with
limits, files written atomically and as sets, the output names, JSON Schema validation, the package's
resources and texture image files. Imports nothing of synthua_usd above it."""
