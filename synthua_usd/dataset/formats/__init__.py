"""Dataset-level annotation formats, each built from the per-image records (plain data, no rendering):
COCO instances (:mod:`.coco`), COCO panoptic (:mod:`.panoptic`), Cityscapes (:mod:`.cityscapes`),
YOLO segmentation (:mod:`.yolo`), the metadata table (:mod:`.tables`), instance previews
(:mod:`.previews`) and one-hot tensors (:mod:`.onehot`)."""
