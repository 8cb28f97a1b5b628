"""The model's files: OBJ (+ MTL + JPEG atlases), binary PLY, binary glTF (GLB), with the CRS beside them.

Written by hand (struct + json; the formats are small and fixed, and no dependency then has to be installed in
QGIS's Python): :func:`glb_bytes` is the one glTF 2.0 encoder, used for model.glb and for the 3D Tiles' contents.

Every file is in the local frame (float32 keeps millimetres near the origin; UTM coordinates would not): the world
coordinate is ``origin + vertex``.  The origin and the CRS are in ``<base>.json`` beside the files, in a comment
of the OBJ and the PLY, in the GLB's ``asset.extras``; the CRS's WKT in ``<base>.prj``.  A block in a model frame
(no CRS) says so in the same places."""
from __future__ import annotations

import json
import os
import struct
from typing import Dict, List, Optional, Sequence, Union

import numpy as np

from ..common.files import atomic_write_text
from .types import MeshPart, TexturedMesh

GREY = (0.6, 0.6, 0.6)  # the colour of the faces no photo sees
_FLOAT, _UINT = 5126, 5125
_ARRAY_BUFFER, _ELEMENT_ARRAY_BUFFER = 34962, 34963
GLB_MAGIC = 0x46546C67  # "glTF"
_JSON_CHUNK, _BIN_CHUNK = 0x4E4F534A, 0x004E4942


def frame_note(mesh: TexturedMesh) -> str:
    """One line naming the frame: the CRS and the origin, or that the block is in a model frame."""
    o = ", ".join(f"{v:.3f}" for v in mesh.origin)
    if mesh.crs_wkt is None:
        return f"model frame (no CRS: the block has no ground control); world = origin + vertex, origin {o}"
    return f"CRS {mesh.crs_name or 'see .prj'}; world = origin + vertex (x east, y north, z up, metres), origin {o}"


def encode_image(image: np.ndarray, fmt: str = "jpeg", quality: int = 90) -> bytes:
    """An RGB uint8 image as JPEG or PNG bytes."""
    import cv2

    bgr = np.ascontiguousarray(image[:, :, ::-1])
    ok, buf = (cv2.imencode(".jpg", bgr, [cv2.IMWRITE_JPEG_QUALITY, int(quality)]) if fmt == "jpeg"
               else cv2.imencode(".png", bgr))
    if not ok:
        raise RuntimeError(f"the atlas ({image.shape[1]} x {image.shape[0]}) could not be encoded as {fmt}")
    return buf.tobytes()


def _pad4(b: bytes, fill: bytes = b"\0") -> bytes:
    return b + fill * (-len(b) % 4)


def glb_bytes(parts: Union[MeshPart, Sequence[MeshPart]], y_up: bool = True, extras: Optional[dict] = None,
              quality: int = 90, images: Optional[Sequence[Optional[bytes]]] = None) -> bytes:
    """A binary glTF 2.0 of mesh parts, one primitive each (textured: its atlas embedded as JPEG, unlit material;
    untextured: grey).  The vertices are taken as they are, in the frame the caller wants (x east, y north, z up);
    ``y_up`` turns them into glTF's y-up frame, (x, y, z) -> (x, z, -y).  ``images``: the atlases already encoded
    (JPEG bytes, one per part, None for an untextured part), e.g. to encode them once for several files."""
    parts = [parts] if isinstance(parts, MeshPart) else list(parts)
    blob = bytearray()
    views: List[dict] = []
    accessors: List[dict] = []
    doc: Dict = {"asset": {"version": "2.0", "generator": "ArchaeoOrtho"}, "scene": 0, "scenes": [{"nodes": [0]}],
                 "nodes": [{"mesh": 0}], "meshes": [{"primitives": []}], "materials": [], "bufferViews": views,
                 "accessors": accessors, "buffers": [{"byteLength": 0}]}
    if extras:
        doc["asset"]["extras"] = extras

    def view(data: bytes, target: Optional[int] = None) -> int:
        while len(blob) % 4:
            blob.append(0)
        v = {"buffer": 0, "byteOffset": len(blob), "byteLength": len(data)}
        if target:
            v["target"] = target
        blob.extend(data)
        views.append(v)
        return len(views) - 1

    def accessor(arr: np.ndarray, kind: str, comp: int, target: Optional[int], bounds: bool = False) -> int:
        a = {"bufferView": view(arr.tobytes(), target), "componentType": comp, "count": int(len(arr)), "type": kind}
        if bounds:
            a["min"] = [float(x) for x in arr.min(axis=0)]
            a["max"] = [float(x) for x in arr.max(axis=0)]
        accessors.append(a)
        return len(accessors) - 1

    for i, part in enumerate(parts):
        if not len(part.faces):
            continue
        v = np.asarray(part.vertices, dtype=np.float32)
        if y_up:
            v = np.column_stack([v[:, 0], v[:, 2], -v[:, 1]]).astype(np.float32)
        attrs = {"POSITION": accessor(np.ascontiguousarray(v), "VEC3", _FLOAT, _ARRAY_BUFFER, bounds=True)}
        if part.normals is not None:
            n = np.asarray(part.normals, dtype=np.float32)
            n = np.column_stack([n[:, 0], n[:, 2], -n[:, 1]]) if y_up else n
            attrs["NORMAL"] = accessor(np.ascontiguousarray(n, dtype=np.float32), "VEC3", _FLOAT, _ARRAY_BUFFER)
        material: Dict = {"pbrMetallicRoughness": {"metallicFactor": 0.0, "roughnessFactor": 1.0},
                          "doubleSided": True}
        if part.uv is not None and part.atlas is not None:
            attrs["TEXCOORD_0"] = accessor(np.ascontiguousarray(part.uv, dtype=np.float32), "VEC2", _FLOAT,
                                           _ARRAY_BUFFER)
            data = images[i] if images is not None and images[i] is not None else encode_image(part.atlas, "jpeg",
                                                                                                  quality)
            doc.setdefault("images", []).append({"bufferView": view(data), "mimeType": "image/jpeg"})
            doc.setdefault("samplers", [{"magFilter": 9729, "minFilter": 9987, "wrapS": 33071, "wrapT": 33071}])
            doc.setdefault("textures", []).append({"sampler": 0, "source": len(doc["images"]) - 1})
            material["pbrMetallicRoughness"]["baseColorTexture"] = {"index": len(doc["textures"]) - 1}
            material["extensions"] = {"KHR_materials_unlit": {}}
            doc["extensionsUsed"] = ["KHR_materials_unlit"]
        else:
            material["pbrMetallicRoughness"]["baseColorFactor"] = [*GREY, 1.0]
        doc["materials"].append(material)
        idx = accessor(np.ascontiguousarray(part.faces, dtype=np.uint32).ravel(), "SCALAR", _UINT,
                       _ELEMENT_ARRAY_BUFFER)
        doc["meshes"][0]["primitives"].append({"attributes": attrs, "indices": idx,
                                               "material": len(doc["materials"]) - 1, "mode": 4})
    if not doc["meshes"][0]["primitives"]:
        raise ValueError("a GLB needs at least one face")
    while len(blob) % 4:
        blob.append(0)
    doc["buffers"][0]["byteLength"] = len(blob)
    js = _pad4(json.dumps(doc, separators=(",", ":")).encode("utf-8"), b" ")
    total = 12 + 8 + len(js) + 8 + len(blob)
    return b"".join([struct.pack("<III", GLB_MAGIC, 2, total), struct.pack("<II", len(js), _JSON_CHUNK), js,
                     struct.pack("<II", len(blob), _BIN_CHUNK), bytes(blob)])


def mesh_extras(mesh: TexturedMesh) -> dict:
    """The frame of a model, for the GLB's ``asset.extras`` and the JSON sidecar."""
    return {"origin": [float(v) for v in mesh.origin], "crs": mesh.crs_name or None,
            "model_frame": mesh.crs_wkt is None, "axes": "local x east, y north, z up (metres); glTF: y up",
            "note": frame_note(mesh)}


def write_glb(mesh: TexturedMesh, path: str, quality: int = 90,
              images: Optional[Sequence[Optional[bytes]]] = None) -> str:
    with open(path, "wb") as f:
        f.write(glb_bytes(mesh.parts, True, mesh_extras(mesh), quality, images))
    return path


def _lines(fmt: str, rows: np.ndarray) -> str:
    """``fmt`` (one line, with its newline) applied to each row (faster than numpy.savetxt)."""
    return (fmt * len(rows)) % tuple(rows.ravel().tolist()) if len(rows) else ""


def write_obj(mesh: TexturedMesh, path: str, images: Sequence[Optional[bytes]]) -> List[str]:
    """``path`` (.obj) with its .mtl and the atlases ``<base>_<n>.jpg`` (``images``: encoded, one per part);
    the files written."""
    folder, base = os.path.dirname(path), os.path.splitext(os.path.basename(path))[0]
    written = [path]
    mtl = [f"# {frame_note(mesh)}"]
    with open(path, "w", encoding="utf-8", newline="\n") as f:
        f.write(f"# ArchaeoOrtho textured model\n# {frame_note(mesh)}\n")
        f.write("# origin {:.4f} {:.4f} {:.4f}\nmtllib {}.mtl\n".format(*mesh.origin, base))
        nv = nt = 0
        for i, part in enumerate(mesh.parts):
            name = f"atlas_{i}" if part.uv is not None else "untextured"
            mtl.append(f"newmtl {name}\nKa 1 1 1\nKd {' '.join(map(str, GREY)) if part.uv is None else '1 1 1'}\n"
                       "Ks 0 0 0\nillum 1")
            f.write(f"o part_{i}\n")
            f.write(_lines("v %.4f %.4f %.4f\n", part.vertices))
            fc = part.faces.astype(np.int64) + 1 + nv
            if part.uv is not None:
                jpg = f"{base}_{i}.jpg"
                with open(os.path.join(folder, jpg), "wb") as g:
                    g.write(images[i])
                written.append(os.path.join(folder, jpg))
                mtl[-1] += f"\nmap_Kd {jpg}"
                uv = np.column_stack([part.uv[:, 0], 1.0 - part.uv[:, 1]])  # OBJ's v goes up
                f.write(_lines("vt %.6f %.6f\n", uv))
                ft = part.faces.astype(np.int64) + 1 + nt
                f.write(f"usemtl {name}\n")
                f.write(_lines("f %d/%d %d/%d %d/%d\n",
                               np.column_stack([fc[:, 0], ft[:, 0], fc[:, 1], ft[:, 1], fc[:, 2], ft[:, 2]])))
                nt += len(uv)
            else:
                f.write(f"usemtl {name}\n")
                f.write(_lines("f %d %d %d\n", fc))
            nv += len(part.vertices)
    atomic_write_text(os.path.join(folder, base + ".mtl"), "\n".join(mtl) + "\n")
    written.append(os.path.join(folder, base + ".mtl"))
    return written


def welded(mesh: TexturedMesh):
    """(world vertices (N, 3) float64, faces (M, 3)) of all parts, the vertices the charts duplicated merged."""
    v = np.concatenate([p.vertices for p in mesh.parts]) if mesh.parts else np.zeros((0, 3), np.float32)
    offs = np.cumsum([0] + [len(p.vertices) for p in mesh.parts])
    f = (np.concatenate([p.faces.astype(np.int64) + o for p, o in zip(mesh.parts, offs)]) if mesh.parts
         else np.zeros((0, 3), np.int64))
    uniq, inv = np.unique(v, axis=0, return_inverse=True)
    return mesh.origin[None, :] + uniq.astype(np.float64), inv.ravel()[f]


def write_ply(mesh: TexturedMesh, path: str) -> str:
    """A binary little-endian PLY of the geometry in world coordinates (float64), the vertices welded."""
    v, f = welded(mesh)
    head = ["ply", "format binary_little_endian 1.0", "comment ArchaeoOrtho model geometry",
            f"comment {frame_note(mesh)}", "comment vertices are world coordinates (float64)",
            f"element vertex {len(v)}", "property double x", "property double y", "property double z",
            f"element face {len(f)}", "property list uchar uint vertex_indices", "end_header"]
    faces = np.zeros(len(f), dtype=[("n", "u1"), ("i", "<u4", (3,))])
    faces["n"] = 3
    faces["i"] = f
    with open(path, "wb") as fh:
        fh.write(("\n".join(head) + "\n").encode("ascii"))
        fh.write(np.ascontiguousarray(v, dtype="<f8").tobytes())
        fh.write(faces.tobytes())
    return path


def write_frame(mesh: TexturedMesh, folder: str, base: str, extra: Optional[dict] = None) -> List[str]:
    """``<base>.json`` (origin, CRS, the figures in ``extra``) and ``<base>.prj`` (the CRS's WKT, when it has
    one)."""
    out = [os.path.join(folder, base + ".json")]
    atomic_write_text(out[0], json.dumps({**mesh_extras(mesh), "crs_wkt": mesh.crs_wkt, **(extra or {})}, indent=1))
    if mesh.crs_wkt:
        out.append(os.path.join(folder, base + ".prj"))
        atomic_write_text(out[1], mesh.crs_wkt)
    return out
