#!/usr/bin/python3
"""Writes scenes/gltf/objects.gltf: a UV sphere and a box as glTF 2.0 meshes with normals, uvs and
metallic-roughness materials, placed by node transforms (translation, rotation, scale), with the
binary data embedded as a base64 data URI. Run from the repository root: scripts/make-gltf-scene.py"""
import base64
import json
import math
import struct


def uv_sphere(n_phi=32, n_theta=16):
    pos, nor, uv, idx = [], [], [], []
    for j in range(n_theta + 1):
        theta = math.pi * j / n_theta
        for i in range(n_phi + 1):
            phi = 2 * math.pi * i / n_phi
            p = (math.sin(theta) * math.cos(phi), math.cos(theta), math.sin(theta) * math.sin(phi))
            pos.append(p)
            nor.append(p)
            uv.append((i / n_phi, j / n_theta))
    for j in range(n_theta):
        for i in range(n_phi):
            a, b = j * (n_phi + 1) + i, (j + 1) * (n_phi + 1) + i
            idx += [a, a + 1, b, a + 1, b + 1, b]  # counter-clockwise seen from outside
    return pos, nor, uv, idx


def box():
    pos, nor, uv, idx = [], [], [], []
    for axis in range(3):
        for sign in (-1, 1):
            n = [0, 0, 0]
            n[axis] = sign
            u_axis, v_axis = (axis + 1) % 3, (axis + 2) % 3
            base = len(pos)
            for (a, b) in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
                p = [0, 0, 0]
                p[axis], p[u_axis], p[v_axis] = sign, a, b
                pos.append(tuple(p))
                nor.append(tuple(n))
                uv.append(((a + 1) / 2, (b + 1) / 2))
            quad = [base, base + 1, base + 2, base, base + 2, base + 3]
            if sign < 0:
                quad = [base, base + 2, base + 1, base, base + 3, base + 2]
            idx += quad
    return pos, nor, uv, idx


def main():
    blob = bytearray()
    views, accessors, meshes = [], [], []

    def add(data, fmt, count, type_, target, minmax=None):
        while len(blob) % 4:
            blob.append(0)
        offset = len(blob)
        for item in data:
            blob.extend(struct.pack(fmt, *(item if isinstance(item, tuple) else (item,))))
        views.append({"buffer": 0, "byteOffset": offset, "byteLength": len(blob) - offset, "target": target})
        acc = {"bufferView": len(views) - 1, "componentType": 5125 if fmt == "<I" else 5126, "count": count, "type": type_}
        if minmax:
            acc["min"], acc["max"] = minmax
        accessors.append(acc)
        return len(accessors) - 1

    for name, (pos, nor, uv, idx), material in (("sphere", uv_sphere(), 0), ("box", box(), 1)):
        lo = [min(p[k] for p in pos) for k in range(3)]
        hi = [max(p[k] for p in pos) for k in range(3)]
        attributes = {
            "POSITION": add(pos, "<3f", len(pos), "VEC3", 34962, (lo, hi)),
            "NORMAL": add(nor, "<3f", len(nor), "VEC3", 34962),
            "TEXCOORD_0": add(uv, "<2f", len(uv), "VEC2", 34962),
        }
        indices = add(idx, "<I", len(idx), "SCALAR", 34963)
        meshes.append({"name": name, "primitives": [{"attributes": attributes, "indices": indices, "material": material, "mode": 4}]})

    s = math.sin(math.radians(30) / 2)
    gltf = {
        "asset": {"version": "2.0", "generator": "penumbra scripts/make-gltf-scene.py"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [
            {"name": "group", "translation": [0, 0, 0], "children": [1, 2]},
            {"name": "gold sphere", "mesh": 0, "translation": [-0.7, 0.6, 0], "scale": [0.6, 0.6, 0.6]},
            {"name": "red box", "mesh": 1, "translation": [0.8, 0.45, 0.1], "rotation": [0, s, 0, math.cos(math.radians(30) / 2)],
             "scale": [0.45, 0.45, 0.45]},
        ],
        "meshes": meshes,
        "materials": [
            {"name": "gold", "pbrMetallicRoughness": {"baseColorFactor": [1.0, 0.78, 0.34, 1], "metallicFactor": 1.0, "roughnessFactor": 0.3}},
            {"name": "red plastic", "pbrMetallicRoughness": {"baseColorFactor": [0.7, 0.08, 0.06, 1], "metallicFactor": 0.0, "roughnessFactor": 0.5}},
        ],
        "buffers": [{"byteLength": len(blob), "uri": "data:application/octet-stream;base64," + base64.b64encode(bytes(blob)).decode()}],
        "bufferViews": views,
        "accessors": accessors,
    }
    with open("scenes/gltf/objects.gltf", "w") as f:
        json.dump(gltf, f, indent=1)


if __name__ == "__main__":
    main()
