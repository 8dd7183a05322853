"""A small glTF 2.0 evaluator for the rig tests: a .glb's accessors, its nodes' transforms at an
animation time (LINEAR, STEP and CUBICSPLINE; rotations by slerp), and a primitive posed there:
morph targets by their animated weights, then skinning (the sum of the weights' joint matrices,
each joint's world matrix times its inverse bind matrix), as the glTF 2.0 specification says.
Written from the specification, independently of the library it checks."""

import json
import struct

import numpy as np

COMPONENTS = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT4": 16}
TYPES = {5120: "<i1", 5121: "<u1", 5122: "<i2", 5123: "<u2", 5125: "<u4", 5126: "<f4"}
NORMALIZE = {5120: 127.0, 5121: 255.0, 5122: 32767.0, 5123: 65535.0}


class Gltf:
    def __init__(self, path):
        data = open(path, "rb").read()
        assert data[:4] == b"glTF", f"{path} is not a .glb"
        length = struct.unpack("<I", data[12:16])[0]
        self.json = json.loads(data[20:20 + length])
        at = 20 + length
        self.bin = data[at + 8:at + 8 + struct.unpack("<I", data[at:at + 4])[0]]
        self.parent = {}
        for n, node in enumerate(self.json["nodes"]):
            for c in node.get("children", []):
                self.parent[c] = n

    def accessor(self, index):
        a = self.json["accessors"][index]
        k, dtype = COMPONENTS[a["type"]], np.dtype(TYPES[a["componentType"]])
        view = self.json["bufferViews"][a["bufferView"]]
        start = view.get("byteOffset", 0) + a.get("byteOffset", 0)
        stride = view.get("byteStride", 0) or k * dtype.itemsize
        rows = [np.frombuffer(self.bin, dtype, k, start + i * stride) for i in range(a["count"])]
        out = np.array(rows, dtype=float).reshape(a["count"], k)
        if a.get("normalized"):
            out = np.maximum(out / NORMALIZE[a["componentType"]], -1.0)
        assert "sparse" not in a, "sparse accessors are not read here"
        return out

    def raw(self, index):
        """An accessor's bytes as the file holds them."""
        a = self.json["accessors"][index]
        view = self.json["bufferViews"][a["bufferView"]]
        start = view.get("byteOffset", 0) + a.get("byteOffset", 0)
        return self.bin[start:start + view["byteLength"] - a.get("byteOffset", 0)]

    def channels(self, animation):
        """{(node, path): (times, values, interpolation)} of an animation."""
        a = self.json["animations"][animation]
        out = {}
        for c in a["channels"]:
            s = a["samplers"][c["sampler"]]
            out[(c["target"].get("node"), c["target"]["path"])] = (
                self.accessor(s["input"])[:, 0], self.accessor(s["output"]),
                s.get("interpolation", "LINEAR"))
        return out

    def local(self, node, animated, time):
        n = self.json["nodes"][node]
        if "matrix" in n:
            return np.array(n["matrix"], dtype=float).reshape(4, 4).T
        t = np.array(n.get("translation", [0, 0, 0]), dtype=float)
        r = np.array(n.get("rotation", [0, 0, 0, 1]), dtype=float)
        s = np.array(n.get("scale", [1, 1, 1]), dtype=float)
        if animated is not None:
            for path in ("translation", "rotation", "scale"):
                if (node, path) in animated:
                    value = sample(*animated[(node, path)], time, path == "rotation")
                    t, r, s = ((value, r, s) if path == "translation"
                               else (t, value, s) if path == "rotation" else (t, r, value))
        m = np.eye(4)
        m[:3, :3] = quaternion_matrix(r) * s
        m[:3, 3] = t
        return m

    def world(self, node, animated=None, time=0.0):
        m = self.local(node, animated, time)
        while node in self.parent:
            node = self.parent[node]
            m = self.local(node, animated, time) @ m
        return m

    def skin_matrices(self, skin, animated=None, time=0.0):
        """Each joint's world matrix times its inverse bind matrix, and the inverse binds."""
        s = self.json["skins"][skin]
        ibm = self.accessor(s["inverseBindMatrices"]).reshape(-1, 4, 4).transpose(0, 2, 1)
        return np.array([self.world(j, animated, time) @ ibm[k]
                         for k, j in enumerate(s["joints"])]), ibm

    def posed(self, mesh_node, animated=None, time=0.0, primitive=0):
        """The primitive's positions at `time`: morphed, then skinned (or its node's world)."""
        node = self.json["nodes"][mesh_node]
        mesh = self.json["meshes"][node["mesh"]]
        prim = mesh["primitives"][primitive]
        x = self.accessor(prim["attributes"]["POSITION"])
        weights = np.array(mesh.get("weights", [0.0] * len(prim.get("targets", []))))
        if animated is not None and (mesh_node, "weights") in animated:
            weights = sample(*animated[(mesh_node, "weights")], time, False,
                             len(prim.get("targets", [])))
        for w, target in zip(weights, prim.get("targets", [])):
            if "POSITION" in target:
                x = x + w * self.accessor(target["POSITION"])
        if "skin" not in node:
            w = self.world(mesh_node, animated, time)
            return x @ w[:3, :3].T + w[:3, 3]
        matrices, _ = self.skin_matrices(node["skin"], animated, time)
        joints = self.accessor(prim["attributes"]["JOINTS_0"]).astype(int)
        w = self.accessor(prim["attributes"]["WEIGHTS_0"])
        blended = np.einsum("vk,vkij->vij", w, matrices[joints])
        return np.einsum("vij,vj->vi", blended[:, :3, :3], x) + blended[:, :3, 3]


def ring_rotations(rest, deformed, triangles):
    """Each vertex's rotation fitted to its welded one-ring's edges, rest to deformed (the polar
    factor of the sum of e' e^T over the triangles' edges at every vertex at the same rest
    position), and its angle in degrees."""
    key = {}
    weld = np.array([key.setdefault(tuple(p), len(key)) for p in rest])
    cov = np.zeros((len(key), 3, 3))
    for a, b in ((0, 1), (1, 2), (2, 0)):
        i, j = triangles[:, a], triangles[:, b]
        outer = np.einsum("ei,ej->eij", deformed[j] - deformed[i], rest[j] - rest[i])
        np.add.at(cov, weld[i], outer)
        np.add.at(cov, weld[j], outer)
    U, _, Wt = np.linalg.svd(cov)
    d = np.sign(np.linalg.det(U @ Wt))
    R = np.einsum("kij,kj,kjl->kil", U, np.stack([np.ones_like(d), np.ones_like(d), d], 1), Wt)
    angle = np.degrees(np.arccos(np.clip((np.trace(R, axis1=1, axis2=2) - 1) / 2, -1, 1)))
    return R[weld], angle[weld]


def quaternion_matrix(q):
    x, y, z, w = q / np.linalg.norm(q)
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def slerp(a, b, u):
    d = float(np.dot(a, b))
    if d < 0:
        b, d = -b, -d
    if d > 0.9995:
        q = a + u * (b - a)
        return q / np.linalg.norm(q)
    theta = np.arccos(d)
    return (np.sin((1 - u) * theta) * a + np.sin(u * theta) * b) / np.sin(theta)


def sample(times, values, interpolation, time, rotation, width=None):
    """A sampler's value at `time` (clamped to its keys)."""
    k = width or values.shape[1]
    if interpolation == "CUBICSPLINE":
        values = values.reshape(len(times), 3, -1)
        tangent_in, value, tangent_out = values[:, 0], values[:, 1], values[:, 2]
    else:
        value = values.reshape(len(times), -1)
    if time <= times[0]:
        return value[0][:k]
    if time >= times[-1]:
        return value[-1][:k]
    i = int(np.searchsorted(times, time, side="right")) - 1
    dt = times[i + 1] - times[i]
    u = (time - times[i]) / dt
    if interpolation == "STEP":
        out = value[i]
    elif interpolation == "CUBICSPLINE":
        u2, u3 = u * u, u * u * u
        out = ((2 * u3 - 3 * u2 + 1) * value[i] + (u3 - 2 * u2 + u) * dt * tangent_out[i]
               + (-2 * u3 + 3 * u2) * value[i + 1] + (u3 - u2) * dt * tangent_in[i + 1])
        if rotation:
            out = out / np.linalg.norm(out)
    elif rotation:
        out = slerp(value[i], value[i + 1], u)
    else:
        out = (1 - u) * value[i] + u * value[i + 1]
    return out[:k]
