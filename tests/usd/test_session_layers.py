"""Composing over an opened stage without touching its files: a stage composed again without its session layer's
work, a subtree swapped between layers, the randomisation layers a stage composes through its session layer, a
sequence's crowd layer swapped in."""

import hashlib

from pxr import Sdf, Usd

from synthua_usd.composition.scenario import RANDOM_ROOT
from synthua_usd.usd.session_layers import (RandomisationLayers, extend_end_time_code, recompose, replace_subtree,
                                            use_session_sublayer)


def layer(text: str, doc: str = "") -> Sdf.Layer:
    """An anonymous layer holding ``text`` (usda prims on one line) with ``doc`` as its documentation."""
    out = Sdf.Layer.CreateAnonymous(".usda")
    body = text.replace("{", "{\n").replace("}", "\n}\n")  # the usda parser wants a prim's braces on lines of their own
    out.ImportFromString(f'#usda 1.0\n(\n    doc = "{doc}"\n)\n{body}')
    return out


def prims(source) -> set[str]:
    """Prim paths of a layer's specs, or of a stage's composed (active) prims."""
    if isinstance(source, Sdf.Layer):
        found = []
        source.Traverse(Sdf.Path.absoluteRootPath, lambda p: found.append(str(p)) if p.IsPrimPath() else None)
        return set(found)
    return {str(p.GetPath()) for p in source.Traverse()}


WORLD = 'def Xform "World" {{ {} }}'
RANDOM = 'def Xform "Randomisation" {{ {} }}'


def test_replace_subtree_swaps_the_root_and_documentation_and_keeps_the_rest():
    target = layer(WORLD.format('over "Agents" (active = false) {} ' + RANDOM.format('def Xform "Old" { def Xform "Leaf" {} }')),
                   doc="scene 1")
    target.subLayerPaths.append("prototypes.usdc")
    fresh = layer(WORLD.format(RANDOM.format('def Xform "New" {}') + ' def Xform "Outside" {}'), doc="scene 2")
    replace_subtree(target, fresh, RANDOM_ROOT)
    assert prims(target) == {"/World", "/World/Agents", "/World/Randomisation", "/World/Randomisation/New"}
    assert target.documentation == "scene 2" and list(target.subLayerPaths) == ["prototypes.usdc"]
    assert target.GetPrimAtPath("/World/Agents").active is False  # outside the root: untouched, fresh's not copied


def test_replace_subtree_removes_the_root_where_the_fresh_layer_has_none():
    target = layer(WORLD.format(RANDOM.format('def Xform "Old" {}')))
    replace_subtree(target, layer(WORLD.format("")), RANDOM_ROOT)
    assert prims(target) == {"/World"} and target.documentation == ""


def scenario_stage() -> Usd.Stage:
    root = layer(WORLD.format('def Xform "Twin" {} def Xform "Agents" { def Xform "Agent_0001" {} }'))
    return Usd.Stage.Open(root, Sdf.Layer.CreateAnonymous("session.usda"))


def test_recompose_leaves_out_the_session_layer_and_deactivates_what_is_asked():
    stage = scenario_stage()
    with Usd.EditContext(stage, stage.GetSessionLayer()):
        stage.DefinePrim("/World/Session")
    base = recompose(stage, "base-session.usda")
    assert prims(base) == {"/World", "/World/Twin", "/World/Agents", "/World/Agents/Agent_0001"}
    assert base.GetSessionLayer() != stage.GetSessionLayer() and base.GetRootLayer() == stage.GetRootLayer()
    twin = recompose(stage, "twin-session.usda", inactive=("/World/Agents", "/World/Missing"))
    assert prims(twin) == {"/World", "/World/Twin"}
    assert "/World/Agents/Agent_0001" in prims(stage)
    assert not stage.GetRootLayer().GetPrimAtPath("/World/Agents").HasInfo("active")  # the files as they were


def test_randomisation_layers_compose_through_the_session_layer_scene_by_scene_and_view_by_view(tmp_path):
    stage = scenario_stage()
    stage.GetSessionLayer().subLayerPaths.append("crowd.usda")  # another's sublayer stays, after the view layer
    layers = RandomisationLayers(stage)
    assert list(stage.GetSessionLayer().subLayerPaths) == [layers.view.identifier, "crowd.usda"]
    assert list(layers.view.subLayerPaths) == [layers.scene.identifier]
    assert list(layers.scene.subLayerPaths) == [layers.prototypes.identifier]

    protos = layer(WORLD.format(RANDOM.format('class "Prototypes" { def Xform "Body_1" {} }')))
    scene = layer(WORLD.format('over "Agents" (active = false) {} ' + RANDOM.format('def Xform "Crowd" { def Xform "P1" {} }')),
                  doc="scene 1")
    scene.subLayerPaths.append("elsewhere.usdc")  # a fresh layer's sublayers are not the stage's
    layers.set_scene(protos, scene)
    assert list(layers.scene.subLayerPaths) == [layers.prototypes.identifier]
    assert "/World/Randomisation/Crowd/P1" in prims(stage) and "/World/Agents" not in prims(stage)

    second = layer(WORLD.format(RANDOM.format('def Xform "Crowd" { def Xform "P2" {} }')), doc="scene 2")
    layers.set_scene(layer(WORLD.format(RANDOM.format('class "Prototypes" { def Xform "Body_2" {} }'))), second)
    assert prims(layers.scene) == {"/World", "/World/Agents", "/World/Randomisation", "/World/Randomisation/Crowd",
                                   "/World/Randomisation/Crowd/P2"}  # the crowd deactivated still: kept from the first
    assert layers.scene.documentation == "scene 2"
    assert "/World/Randomisation/Prototypes/Body_2" in prims(layers.prototypes)
    assert "/World/Randomisation/Prototypes/Body_1" not in prims(layers.prototypes)

    view = layer(WORLD.format(RANDOM.format('over "Crowd" { over "P2" (active = false) {} }')), doc="a view")
    authored = view.ExportToString()
    assert layers.set_view(view) == hashlib.sha256(authored.encode("utf-8")).hexdigest()
    assert list(layers.view.subLayerPaths) == [layers.scene.identifier]
    assert "/World/Randomisation/Crowd/P2" not in prims(stage)

    out, scene_path, proto_path = layers.export(tmp_path / "layer.usda")
    assert [p.name for p in (out, scene_path, proto_path)] == ["layer.usda", "layer.scene.usda", "layer.prototypes.usdc"]
    assert list(Sdf.Layer.FindOrOpen(str(out)).subLayerPaths) == ["./layer.scene.usda"]

    layers.close()
    assert list(stage.GetSessionLayer().subLayerPaths) == ["crowd.usda"]
    assert "/World/Randomisation" not in prims(stage) and "/World/Agents" in prims(stage)
    layers.close()  # twice: nothing more to take out


def test_a_session_sublayer_replaces_the_others_named_and_the_end_time_code_only_grows(tmp_path):
    paths = []
    for name in ("a", "b"):
        paths.append(str(tmp_path / f"crowd_{name}.usda"))
        layer(WORLD.format(f'def Xform "Crowd_{name}" {{}}')).Export(paths[-1])
    stage = scenario_stage()
    stage.GetSessionLayer().subLayerPaths.append("other.usda")
    use_session_sublayer(stage, paths[0], among=paths)
    use_session_sublayer(stage, paths[1], among=paths)
    assert list(stage.GetSessionLayer().subLayerPaths) == ["other.usda", paths[1]]
    assert "/World/Crowd_b" in prims(stage) and "/World/Crowd_a" not in prims(stage)
    extend_end_time_code(stage, 48.0)
    extend_end_time_code(stage, 12.0)
    assert stage.GetEndTimeCode() == 48.0 and stage.GetSessionLayer().endTimeCode == 48.0
    assert not stage.GetRootLayer().HasEndTimeCode()
