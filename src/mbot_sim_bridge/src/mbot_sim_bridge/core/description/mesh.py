"""Triangle meshes for collision geometry: STL (ASCII and binary), Wavefront OBJ and COLLADA.

Every reader returns the same thing: welded vertices in metres and triangle indices, so one code path builds
PyBullet shapes and map outlines from any format. STL and OBJ are read by trimesh; COLLADA by pycollada,
because Gazebo honours its ``<unit meter>`` and node transforms (but not ``<up_axis>``), which the reader below
applies exactly. STL and OBJ carry no units and are read as metres. pycollada is imported only when a .dae
file is read.
"""
import os
import struct
import warnings
from dataclasses import dataclass
from xml.etree import ElementTree

import numpy as np

from ..errors import ModelError
from ..xml_values import read_regular_file

PYCOLLADA_REQUIREMENT = "pycollada==0.9.3"


@dataclass(frozen=True, eq=False)
class TriangleMesh:
    vertices: np.ndarray  # (N, 3) float, metres, no duplicates
    triangles: np.ndarray  # (M, 3) int, indices into vertices

    def scaled(self, scale) -> "TriangleMesh":
        """The mesh with SDF ``<mesh><scale>`` applied per axis."""
        return TriangleMesh(self.vertices * np.asarray(scale, dtype=float), self.triangles)


def load_mesh(path: str) -> TriangleMesh:
    """Read ``path`` by its extension; raise ModelError naming the file when it cannot be used."""
    readers = {".stl": _read_with_trimesh, ".obj": _read_with_trimesh, ".dae": _read_collada}
    extension = os.path.splitext(path)[1].lower()
    if extension not in readers:
        raise ModelError(f"{path}: unsupported mesh format '{extension}' (supported: {', '.join(sorted(readers))})")
    read_regular_file(path, ModelError)  # a FIFO or a device would block the reader: refuse it unopened
    try:
        corners = readers[extension](path)
    except OSError as error:
        raise ModelError(f"{path}: cannot read mesh: {error.strerror or error}") from error
    except (ValueError, IndexError, KeyError, TypeError) as error:
        raise ModelError(f"{path}: malformed mesh: {error or type(error).__name__}") from error
    if len(corners) == 0:
        raise ModelError(f"{path}: mesh has no triangles")
    if not np.all(np.isfinite(corners)):
        raise ModelError(f"{path}: mesh has non-finite coordinates")
    return _welded(corners)


def pybullet_reads_stl(path: str) -> bool:
    """Whether PyBullet's URDF importer reads this STL: it takes only binary STL whose size matches the triangle
    count in its header, and gives a link no collision at all for any other (an ASCII STL, which Gazebo reads)."""
    with open(path, "rb") as stream:
        header = stream.read(84)
        size = os.fstat(stream.fileno()).st_size
    return len(header) == 84 and size == 84 + 50 * struct.unpack("<I", header[80:])[0]


def write_binary_stl(mesh: TriangleMesh, path: str):
    corners = mesh.vertices[mesh.triangles].astype(np.float32)
    normals = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    lengths = np.linalg.norm(normals, axis=1, keepdims=True)
    normals = np.divide(normals, lengths, out=np.zeros_like(normals), where=lengths > 0)
    rows = np.zeros(len(corners), dtype=[("normal", "<f4", 3), ("corners", "<f4", (3, 3)), ("attribute", "<u2")])
    rows["normal"], rows["corners"] = normals, corners
    with open(path, "wb") as stream:
        stream.write(b"binary copy for PyBullet".ljust(80, b" ") + struct.pack("<I", len(rows)))
        stream.write(rows.tobytes())


def with_pybullet_readable_meshes(urdf: str, folder: str) -> str:
    """``urdf`` with each STL that PyBullet would not read (see pybullet_reads_stl) replaced by a binary copy
    written in ``folder``; ModelError names a file that cannot be read at all."""
    if ".stl" not in urdf.lower():
        return urdf
    root = ElementTree.fromstring(urdf)
    copies = {}
    for mesh in root.iter("mesh"):
        path = mesh.get("filename", "")
        path = path[len("file://"):] if path.startswith("file://") else path
        try:
            if not path.lower().endswith(".stl") or pybullet_reads_stl(path):
                continue
        except OSError as error:
            raise ModelError(f"{path}: cannot read mesh: {error.strerror or error}") from None
        if path not in copies:
            copies[path] = os.path.join(folder, f"{len(copies)}.stl")
            write_binary_stl(load_mesh(path), copies[path])
        mesh.set("filename", copies[path])
    return ElementTree.tostring(root, encoding="unicode") if copies else urdf


def _welded(corners: np.ndarray) -> TriangleMesh:
    """(M, 3, 3) triangle corners -> shared vertices; STL repeats each vertex in every triangle that uses it."""
    vertices, inverse = np.unique(corners.reshape(-1, 3), axis=0, return_inverse=True)
    return TriangleMesh(vertices, inverse.reshape(-1, 3))


def _read_with_trimesh(path: str) -> np.ndarray:
    import trimesh  # here, not at the top: importing it costs the node's start-up about a second
    # process=False keeps the file's triangles as they are; _welded merges the duplicate corners.
    mesh = trimesh.load(path, force="mesh", process=False)
    if not isinstance(mesh, trimesh.Trimesh):
        raise ValueError("no triangles could be read")
    return np.asarray(mesh.triangles, dtype=float).reshape(-1, 3, 3)


def _read_collada(path: str) -> np.ndarray:
    try:
        import collada
    except ImportError:
        raise ModelError(f"{path}: reading COLLADA needs pycollada: pip install {PYCOLLADA_REQUIREMENT}") from None
    corners = []
    try:
        with warnings.catch_warnings():
            # pycollada keeps node transforms as numpy.matrix; numpy's notice about that is not ours to act on.
            warnings.simplefilter("ignore", PendingDeprecationWarning)
            document = collada.Collada(path)
            if document.scene is None:
                raise ValueError("no <scene> to take the geometry from")
            for geometry in document.scene.objects("geometry"):  # node transforms applied
                for primitive in geometry.primitives():
                    if isinstance(primitive, collada.polylist.BoundPolylist):
                        primitive = primitive.triangleset()
                    if isinstance(primitive, collada.triangleset.BoundTriangleSet) and len(primitive.vertex_index):
                        corners.append(primitive.vertex[primitive.vertex_index])
    except (collada.DaeError, KeyError, IndexError) as error:
        raise ValueError(str(error) or type(error).__name__) from error
    if not corners:
        return np.empty((0, 3, 3))
    unit = document.assetInfo.unitmeter or 1.0
    return np.concatenate(corners).astype(float) * unit
