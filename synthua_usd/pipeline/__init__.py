"""Jobs that join the parts: read a stage (usd), render it (backends), write the outputs (the dataset formats, image
files through core), and train and score the detector (:mod:`.detector`: an Ultralytics job run in its own
interpreter)."""
