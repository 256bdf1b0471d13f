"""The object detector of `synthua train` and `synthua evaluate-real`: Ultralytics YOLO (AGPL-3.0), run in a
virtual environment of its own (``tools/setup_train.sh`` makes ``.venv-train``), never in synthua's. The script that
interpreter runs (:mod:`.yolo_job`, which alone imports ``ultralytics`` and ``torch``), the data it trains on
(:mod:`.yolo_data`: a detection set in Ultralytics' box layout) and the runner that starts it (:mod:`.runner`)."""
