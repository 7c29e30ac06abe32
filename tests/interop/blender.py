"""Opens a snakeskin glTF in Blender and checks that its importer built the material the file
describes; optionally adds the film by hand (README, "Blender") and renders with Cycles.

Blender is the tool many artists will open these files in, and its glTF importer is not the
three.js loader that tests/gltf.rs runs in CI. This check is run by hand, not in CI: it needs
Blender as a Python module (`pip install bpy`, about 820 MB installed, for the Python version
that bpy release was built for: 3.11 for bpy 5.0).

    python3 -m venv venv && venv/bin/pip install bpy
    snakeskin export xenopeltis-unicolor --gltf xeno.glb --size 512
    venv/bin/python tests/interop/blender.py xeno.glb [--film] [--render out.png]

Checks, against the file's own JSON: Base Color from the base colour image (sRGB); Normal from
a tangent-space Normal Map node on the normal image (Non-Color); Roughness from the green
channel of the metallic-roughness image (Non-Color) and Metallic from its blue; IOR =
KHR_materials_ior. The film (KHR_materials_iridescence) is reported, not checked: Blender 5.0
drops it without a message. `--film` wires it as README says: the thickness image's green
channel, mapped from 0..1 to the extension's minimum..maximum nm, into Thin Film Thickness,
and Thin Film IOR = iridescenceIor. Prints a JSON report; exits 1 if a check fails.
"""

import argparse
import json
import math
import os
import struct
import sys
import tempfile
import urllib.parse

import bpy
import mathutils


def gltf_json(path):
    """The glTF's JSON (a .gltf, or the first chunk of a .glb) and the glb's binary chunk."""
    data = open(path, "rb").read()
    if data[:4] != b"glTF":
        return json.loads(data), None
    length, kind = struct.unpack_from("<I4s", data, 12)
    assert kind == b"JSON", "a glb's first chunk is its JSON"
    document = json.loads(data[20 : 20 + length])
    start = 20 + length
    binary_length = struct.unpack_from("<I", data, start)[0]
    return document, data[start + 8 : start + 8 + binary_length]


def feeding(socket):
    """The node that feeds `socket` and the output it feeds from, or (None, None)."""
    if not socket.is_linked:
        return None, None
    link = socket.links[0]
    return link.from_node, link.from_socket.name


def image_of(node):
    """The image an Image Texture node reads, as (name, colour space), or None."""
    if node is None or node.bl_idname != "ShaderNodeTexImage" or node.image is None:
        return None
    return node.image.name, node.image.colorspace_settings.name


def image_name(document, texture_info):
    """What the importer names the image a texture slot points at (its name, else its uri)."""
    image = document["images"][document["textures"][texture_info["index"]]["source"]]
    return image.get("name") or os.path.splitext(os.path.basename(image.get("uri", "")))[0]


def inspect(document, material):
    """The Principled BSDF's wiring against what the file's material says: (report, failures)."""
    nodes = material.node_tree.nodes
    bsdf = next(n for n in nodes if n.bl_idname == "ShaderNodeBsdfPrincipled")
    source = document["materials"][0]
    pbr = source["pbrMetallicRoughness"]
    report, failures = {}, []

    def expect(what, found, wanted):
        report[what] = found
        if found != wanted:
            failures.append(f"{what}: found {found}, the file says {wanted}")

    node, _ = feeding(bsdf.inputs["Base Color"])
    expect("base_color", image_of(node), (image_name(document, pbr["baseColorTexture"]), "sRGB"))

    normal_map, _ = feeding(bsdf.inputs["Normal"])
    is_map = normal_map is not None and normal_map.bl_idname == "ShaderNodeNormalMap"
    expect("normal_space", normal_map.space if is_map else None, "TANGENT")
    image = image_of(feeding(normal_map.inputs["Color"])[0]) if is_map else None
    expect("normal", image, (image_name(document, source["normalTexture"]), "Non-Color"))

    orm = image_name(document, pbr["metallicRoughnessTexture"])
    for socket, channel in (("Roughness", "Green"), ("Metallic", "Blue")):
        separate, output = feeding(bsdf.inputs[socket])
        image = image_of(feeding(separate.inputs["Color"])[0]) if separate is not None else None
        expect(socket.lower(), (image, output), ((orm, "Non-Color"), channel))

    ior = source.get("extensions", {}).get("KHR_materials_ior", {}).get("ior", 1.5)
    expect("ior", round(bsdf.inputs["IOR"].default_value, 4), round(ior, 4))

    film = source.get("extensions", {}).get("KHR_materials_iridescence")
    report["file_film"] = film is not None
    report["thin_film_thickness_linked"] = bsdf.inputs["Thin Film Thickness"].is_linked
    report["thin_film_ior"] = round(bsdf.inputs["Thin Film IOR"].default_value, 4)
    return report, failures


def wire_film_by_hand(document, binary, material, folder):
    """README's steps: thickness image (Non-Color) -> Separate Color G -> Map Range (0..1 to
    the extension's min..max nm) -> Thin Film Thickness; Thin Film IOR = iridescenceIor."""
    film = document["materials"][0]["extensions"]["KHR_materials_iridescence"]
    image = document["images"][document["textures"][film["iridescenceThicknessTexture"]["index"]]["source"]]
    if "bufferView" in image:
        view = document["bufferViews"][image["bufferView"]]
        start = view.get("byteOffset", 0)
        path = os.path.join(tempfile.mkdtemp(), "thickness.png")
        open(path, "wb").write(binary[start : start + view["byteLength"]])
    else:
        path = os.path.join(folder, urllib.parse.unquote(image["uri"]))
    tree = material.node_tree
    bsdf = next(n for n in tree.nodes if n.bl_idname == "ShaderNodeBsdfPrincipled")
    texture = tree.nodes.new("ShaderNodeTexImage")
    texture.image = bpy.data.images.load(path)
    texture.image.colorspace_settings.name = "Non-Color"
    separate = tree.nodes.new("ShaderNodeSeparateColor")
    to_nm = tree.nodes.new("ShaderNodeMapRange")
    to_nm.inputs["To Min"].default_value = film["iridescenceThicknessMinimum"]
    to_nm.inputs["To Max"].default_value = film["iridescenceThicknessMaximum"]
    tree.links.new(texture.outputs["Color"], separate.inputs["Color"])
    tree.links.new(separate.outputs["Green"], to_nm.inputs["Value"])
    tree.links.new(to_nm.outputs["Result"], bsdf.inputs["Thin Film Thickness"])
    bsdf.inputs["Thin Film IOR"].default_value = film["iridescenceIor"]


def render(out, size, samples):
    """A Cycles render on the CPU: a grey ground, a sun and a plain sky, the camera near the
    middle of the body (the preview mesh lies along x, its back up)."""
    scene = bpy.context.scene
    bpy.ops.mesh.primitive_plane_add(size=20, location=(0, 0, -0.002))
    ground = bpy.data.materials.new("ground")
    ground.use_nodes = True
    ground.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (0.35, 0.35, 0.33, 1)
    bpy.context.active_object.data.materials.append(ground)
    sun = bpy.data.objects.new("sun", bpy.data.lights.new("sun", "SUN"))
    sun.data.energy, sun.data.angle = 3.0, math.radians(3)
    sun.rotation_euler = (math.radians(40), math.radians(10), math.radians(-30))
    scene.collection.objects.link(sun)
    scene.world = bpy.data.worlds.new("sky")
    scene.world.use_nodes = True
    scene.world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.45, 0.5, 0.6, 1)
    camera = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
    camera.data.lens = 40
    camera.location = (0.25, -0.9, 0.55)
    camera.rotation_euler = (mathutils.Vector((0.2, 0.05, 0.05)) - camera.location).to_track_quat("-Z", "Y").to_euler()
    scene.collection.objects.link(camera)
    scene.camera = camera
    width, height = (int(v) for v in size.split("x"))
    scene.render.resolution_x, scene.render.resolution_y, scene.render.resolution_percentage = width, height, 100
    scene.render.engine = "CYCLES"
    scene.cycles.device, scene.cycles.samples, scene.cycles.use_denoising = "CPU", samples, False
    scene.render.filepath = os.path.abspath(out)
    bpy.ops.render.render(write_still=True)


def main():
    arguments = sys.argv[sys.argv.index("--") + 1 :] if "--" in sys.argv else sys.argv[1:]
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("gltf", help="a .glb or .gltf written by `snakeskin export`")
    parser.add_argument("--film", action="store_true", help="wire the film by hand as README says")
    parser.add_argument("--render", metavar="OUT.png", help="render the snake with Cycles (CPU)")
    parser.add_argument("--size", default="960x540", help="render size, WxH (default 960x540)")
    parser.add_argument("--samples", type=int, default=64, help="Cycles samples (default 64)")
    options = parser.parse_args(arguments)

    document, binary = gltf_json(options.gltf)
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.import_scene.gltf(filepath=os.path.abspath(options.gltf))
    material = next(o for o in bpy.data.objects if o.type == "MESH").data.materials[0]
    report, failures = inspect(document, material)
    report = {"blender": bpy.app.version_string, "file": options.gltf, **report, "failures": failures}
    if options.film and report["file_film"]:
        wire_film_by_hand(document, binary, material, os.path.dirname(os.path.abspath(options.gltf)))
        report["film_wired_by_hand"] = True
    if options.render:
        render(options.render, options.size, options.samples)
        report["render"] = options.render
    print(json.dumps(report, indent=2))
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
