"""Dataset analytics and evaluation: the paper's statistics of a generated dataset (tables, plots, one HTML
report), segmentation metrics of predictions against a dataset's labels, COCO mAP, and a PyTorch dataset."""
