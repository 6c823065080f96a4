"""Triangle meshes for collision geometry: STL (ASCII and binary), Wavefront OBJ and COLLADA.

Every reader returns the same thing: welded vertices in metres and triangle indices, so one code path builds
PyBullet shapes and map outlines from any format. Like Gazebo's loaders, COLLADA honours ``<unit meter>`` and
the node transforms of its visual scene but not ``<up_axis>``; STL and OBJ carry no units and are read as metres.
COLLADA needs pycollada, imported only when a .dae file is read.
"""
import os
import re
import warnings
from dataclasses import dataclass

import numpy as np

from .errors import ModelError

PYCOLLADA_REQUIREMENT = "pycollada==0.9.3"

_STL_HEADER_BYTES = 80
_STL_TRIANGLE = np.dtype([("normal", "<f4", (3,)), ("vertices", "<f4", (3, 3)), ("attribute", "<u2")])
_STL_ASCII_VERTEX = re.compile(rb"vertex\s+(\S+)\s+(\S+)\s+(\S+)")


@dataclass(frozen=True, eq=False)
class TriangleMesh:
    vertices: np.ndarray  # (N, 3) float, metres, no duplicates
    triangles: np.ndarray  # (M, 3) int, indices into vertices

    def scaled(self, scale) -> "TriangleMesh":
        """The mesh with SDF ``<mesh><scale>`` applied per axis."""
        return TriangleMesh(self.vertices * np.asarray(scale, dtype=float), self.triangles)


def load_mesh(path: str) -> TriangleMesh:
    """Read ``path`` by its extension; raise ModelError naming the file when it cannot be used."""
    readers = {".stl": _read_stl, ".obj": _read_obj, ".dae": _read_collada}
    extension = os.path.splitext(path)[1].lower()
    if extension not in readers:
        raise ModelError(f"{path}: unsupported mesh format '{extension}' (supported: {', '.join(sorted(readers))})")
    try:
        corners = readers[extension](path)
    except OSError as error:
        raise ModelError(f"{path}: cannot read mesh: {error.strerror or error}") from error
    except ValueError as error:
        raise ModelError(f"{path}: malformed mesh: {error}") from error
    if len(corners) == 0:
        raise ModelError(f"{path}: mesh has no triangles")
    if not np.all(np.isfinite(corners)):
        raise ModelError(f"{path}: mesh has non-finite coordinates")
    return _welded(corners)


def _welded(corners: np.ndarray) -> TriangleMesh:
    """(M, 3, 3) triangle corners -> shared vertices; STL repeats each vertex in every triangle that uses it."""
    vertices, inverse = np.unique(corners.reshape(-1, 3), axis=0, return_inverse=True)
    return TriangleMesh(vertices, inverse.reshape(-1, 3))


def _read_stl(path: str) -> np.ndarray:
    with open(path, "rb") as stream:
        data = stream.read()
    # Binary files may also begin with "solid", so the size check decides.
    if len(data) >= _STL_HEADER_BYTES + 4:
        count = int(np.frombuffer(data, "<u4", 1, _STL_HEADER_BYTES)[0])
        if len(data) == _STL_HEADER_BYTES + 4 + count * _STL_TRIANGLE.itemsize:
            records = np.frombuffer(data, _STL_TRIANGLE, count, _STL_HEADER_BYTES + 4)
            return records["vertices"].astype(float)
    if not data.lstrip().startswith(b"solid"):
        raise ValueError("neither binary STL (size does not match the triangle count) nor ASCII STL")
    vertices = np.array(_STL_ASCII_VERTEX.findall(data), dtype=float)
    if len(vertices) % 3:
        raise ValueError(f"{len(vertices)} vertices do not make whole triangles")
    return vertices.reshape(-1, 3, 3)


def _read_obj(path: str) -> np.ndarray:
    vertices, triangles = [], []
    with open(path, encoding="utf-8", errors="replace") as stream:
        for number, line in enumerate(stream, start=1):
            fields = line.split()
            if not fields or fields[0] not in ("v", "f"):
                continue
            try:
                if fields[0] == "v":
                    vertices.append(_obj_vertex(fields))
                else:
                    # OBJ polygons are convex by convention: fan them into triangles.
                    corners = _obj_face(fields, len(vertices))
                    triangles.extend((corners[0], corners[i], corners[i + 1]) for i in range(1, len(corners) - 1))
            except ValueError:
                raise ValueError(f"line {number}: bad '{fields[0]}' record '{line.strip()}'") from None
    return np.array(vertices, dtype=float).reshape(-1, 3)[np.array(triangles, dtype=int).reshape(-1, 3)]


def _obj_vertex(fields) -> list:
    if len(fields) < 4:
        raise ValueError("a vertex needs x y z")
    return [float(value) for value in fields[1:4]]


def _obj_face(fields, vertex_count: int) -> list:
    """Corners of "f 1/2/3 4//6 -1": the vertex index comes first, 1-based; negative ones count back."""
    corners = []
    for token in fields[1:]:
        index = int(token.split("/")[0])
        corner = index - 1 if index > 0 else vertex_count + index
        if not 0 <= corner < vertex_count:
            raise ValueError("vertex index out of range")
        corners.append(corner)
    if len(corners) < 3:
        raise ValueError("a face needs three vertices")
    return corners


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
