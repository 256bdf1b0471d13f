"""Scene randomisation as plain data: what a randomised dataset varies (:mod:`config`), the streams its draws
come from (:mod:`streams`), and the draws of one scene (:mod:`scene`: the crowd's cast and looks, devices,
material variants), one view (:mod:`view`: the camera's jitter and where people stand; :mod:`poses`: how they
stand), one image's light (:mod:`light`) and its camera effects (:mod:`effects`; applied by
:mod:`synthua_usd.backends.camera_effects`). USD authoring of the draws is :mod:`synthua_usd.usd.randomisation_layer`;
applying them to a loaded stage, :mod:`synthua_usd.pipeline.randomiser`."""
