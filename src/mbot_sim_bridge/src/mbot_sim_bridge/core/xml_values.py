"""One reader for every value in SDF worlds, URDF robots and plugin tags.

XML is parsed through expat so each element keeps its line number; every error names the document (a file
path, or a label such as "model 'mbot'"), the line and the element, and says what was expected. NaN and
infinities are refused with a message that names them, not as a count problem. The error class comes with
the document: a world raises WorldError, a robot description ModelError, a plugin block ConfigError.
"""
import math
import os
import stat
import xml.etree.ElementTree as ET
from typing import Dict, NamedTuple, Optional, Sequence, Tuple, Type
from xml.parsers import expat

from .errors import BridgeError, WorldError
from .geometry import IDENTITY, Pose, pose_from_xyz_rpy

_TRUE = ("true", "1")
_FALSE = ("false", "0")
# URDF and SDF nest about ten deep; ElementTree serialises and copies recursively, and 100,000 levels ran out of
# Python's stack ("maximum recursion depth exceeded").
MAX_DEPTH = 100
# The largest XML document read, in bytes and in elements. Python's garbage collector scans every element held
# while it reads: at 1.7 million (a 48 MB model) each scan stopped every thread, the loop too, for up to 2 s.
MAX_DOCUMENT_BYTES = 64 << 20
MAX_ELEMENTS = 250_000
# The farthest anything may be placed (m), by a pose, an origin or a service, and the largest size of a shape:
# beyond it Bullet's broadphase and solver overflow or lose all precision (a link at 1e308 m overflowed the lumped
# inertia, "Eigenvalues did not converge"; a box of 1e308 m was frozen and deleted within 10 ms of its spawn).
MAX_POSITION = 1.0e5
MAX_SHAPE_SIZE = MAX_POSITION


class XmlDocument(NamedTuple):
    path: str  # file path, or what the XML is ("model 'mbot'")
    root: ET.Element
    lines: Dict[ET.Element, int]
    error: Type[BridgeError] = WorldError

    def where(self, element: Optional[ET.Element]) -> str:
        line = self.lines.get(element) if element is not None else None
        return f"{self.path}:{line}" if line else self.path

    def fail(self, element: Optional[ET.Element], message: str) -> BridgeError:
        """The document's error, located at ``element``: ``raise document.fail(element, "...")``."""
        return self.error(f"{self.where(element)}: {message}")


def parse_xml(data, path: str, error: Type[BridgeError] = WorldError) -> XmlDocument:
    """ElementTree built through expat, so that every element keeps its line number for messages."""
    if len(data) > MAX_DOCUMENT_BYTES:
        raise error(f"{path}: {len(data) / (1 << 20):.0f} MB of XML; at most {MAX_DOCUMENT_BYTES >> 20} MB is read")
    builder = ET.TreeBuilder(insert_comments=False)
    parser = expat.ParserCreate()
    lines = {}
    depth = [0]

    def start(tag, attributes):
        depth[0] += 1
        if len(lines) >= MAX_ELEMENTS:
            raise error(f"{path}:{parser.CurrentLineNumber}: more than {MAX_ELEMENTS:,} elements; at most that many "
                        "are read")
        if depth[0] > MAX_DEPTH:
            raise error(f"{path}:{parser.CurrentLineNumber}: <{tag}> is nested {depth[0]} elements deep; "
                        f"at most {MAX_DEPTH} are read")
        lines[builder.start(tag, attributes)] = parser.CurrentLineNumber

    def end(tag):
        depth[0] -= 1
        builder.end(tag)

    parser.StartElementHandler = start
    parser.EndElementHandler = end
    parser.CharacterDataHandler = builder.data
    try:
        parser.Parse(data, True)
    except expat.ExpatError as failure:
        raise error(f"{path}:{failure.lineno}: not valid XML: {expat.ErrorString(failure.code)}") from None
    return XmlDocument(path, builder.close(), lines, error)


def read_regular_file(path: str, error: Type[BridgeError] = WorldError) -> bytes:
    """A file's bytes; anything but a regular file (a FIFO, a device) is refused without being opened."""
    try:
        mode = os.stat(path).st_mode
        if not stat.S_ISREG(mode):
            raise error(f"{path}: not a regular file; refused")
        with open(path, "rb") as stream:
            return stream.read()
    except OSError as failure:
        raise error(f"{path}: cannot read: {failure.strerror or failure}") from None


def read_xml_file(path: str, error: Type[BridgeError] = WorldError) -> XmlDocument:
    return parse_xml(read_regular_file(path, error), path, error)


# --- text -> value, shared by the element readers below and by plugin Param tables -----------------------

def parse_bool(text: str) -> bool:
    """Gazebo accepts true/false/1/0 in any case."""
    value = text.strip().lower()
    if value in _TRUE:
        return True
    if value in _FALSE:
        return False
    raise ValueError("expected true, false, 1 or 0")


def parse_floats(text: str, count: Optional[int] = None) -> Tuple[float, ...]:
    """Whitespace-separated finite numbers; ValueError says what is wrong (not a number, NaN, inf, count)."""
    words = text.split()
    try:
        values = tuple(float(word) for word in words)
    except ValueError:
        wanted = "a number" if count == 1 else f"{count} numbers" if count else "numbers"
        raise ValueError(f"expected {wanted}, got '{text.strip()}'") from None
    for value in values:
        if math.isnan(value):
            raise ValueError(f"NaN is not a valid value: '{text.strip()}'")
        if math.isinf(value):
            raise ValueError(f"infinity is not a valid value: '{text.strip()}'")
    if count is not None and len(values) != count:
        raise ValueError(f"expected {count} number{'s' if count != 1 else ''}, got '{text.strip()}'")
    return values


def parse_float(text: str) -> float:
    return parse_floats(text, 1)[0]


def parse_int(text: str) -> int:
    try:
        return int(text.strip())
    except ValueError:
        raise ValueError(f"expected a whole number, got '{text.strip()}'") from None


def check_range(value: float, minimum: Optional[float] = None, maximum: Optional[float] = None,
                exclusive_minimum: bool = False, least_positive: Optional[float] = None) -> None:
    """ValueError naming the valid range when ``value`` is outside it; ``least_positive`` also refuses the
    values between 0 and it (a rate so small that its period overflows)."""
    low_ok = minimum is None or (value > minimum if exclusive_minimum else value >= minimum)
    high_ok = maximum is None or value <= maximum
    tiny = least_positive is not None and 0 < value < least_positive
    if not (low_ok and high_ok) or tiny:
        valid = describe_range(minimum, maximum, exclusive_minimum, least_positive)
        raise ValueError(f"{value:g} is outside the valid range {valid}")


def describe_range(minimum: Optional[float], maximum: Optional[float], exclusive_minimum: bool = False,
                   least_positive: Optional[float] = None) -> str:
    if least_positive is not None:
        at_most_zero = "0" if minimum == 0 else "<= 0"
        return f"{at_most_zero} or >= {least_positive:g}" + ("" if maximum is None else f" and <= {maximum:g}")
    low = "" if minimum is None else f"{'>' if exclusive_minimum else '>='} {minimum:g}"
    high = "" if maximum is None else f"<= {maximum:g}"
    return " and ".join(part for part in (low, high) if part) or "any finite number"


# --- element readers --------------------------------------------------------------------------------------

def read_text(parent: Optional[ET.Element], tag: str) -> str:
    element = parent.find(tag) if parent is not None else None
    return (element.text or "").strip() if element is not None else ""


def _values(element: ET.Element, document: XmlDocument, count: int, name: str) -> Tuple[float, ...]:
    try:
        return parse_floats(element.text or "", count)
    except ValueError as problem:
        raise document.fail(element, f"{name}: {problem}") from None


def read_number(parent: Optional[ET.Element], tag: str, document: XmlDocument, default: Optional[float],
                minimum: Optional[float] = None, maximum: Optional[float] = None,
                positive: bool = False) -> Optional[float]:
    """``<tag>`` below ``parent`` as one finite number; ``positive`` means > 0."""
    element = parent.find(tag) if parent is not None else None
    if element is None:
        return default
    value = _values(element, document, 1, f"<{tag}>")[0]
    try:
        check_range(value, 0.0 if positive else minimum, maximum, exclusive_minimum=positive)
    except ValueError as problem:
        raise document.fail(element, f"<{tag}>: {problem}") from None
    return value


def read_vector(parent: Optional[ET.Element], tag: str, document: XmlDocument, default: Tuple[float, ...],
                count: int = 3, positive: bool = False, maximum: Optional[float] = None) -> Tuple[float, ...]:
    element = parent.find(tag) if parent is not None else None
    if element is None:
        return default
    values = _values(element, document, count, f"<{tag}>")
    if positive and min(values) <= 0.0:
        raise document.fail(element, f"<{tag}> must be positive, got '{element.text.strip()}'")
    if maximum is not None and max(values) > maximum:
        raise document.fail(element, f"<{tag}> must be at most {maximum:g}, got '{element.text.strip()}'")
    return values


def read_pose(element: Optional[ET.Element], document: XmlDocument) -> Pose:
    """SDF ``<pose>x y z roll pitch yaw</pose>`` (R = Rz·Ry·Rx, as URDF); absent or empty is the identity."""
    if element is None or not (element.text or "").strip():
        return IDENTITY
    values = _values(element, document, 6, "<pose> (x y z roll pitch yaw)")
    _check_offset(values[:3], document, element, "<pose>")
    return pose_from_xyz_rpy(values[:3], values[3:])


def _check_offset(position: Sequence[float], document: XmlDocument, element: ET.Element, name: str):
    if max(abs(value) for value in position) > MAX_POSITION:
        raise document.fail(element, f"{name}: position {' '.join(f'{value:g}' for value in position)} is beyond "
                                     f"±{MAX_POSITION:g} m")


def read_bool(element: Optional[ET.Element], document: XmlDocument, default: bool = False) -> bool:
    if element is None:
        return default
    try:
        return parse_bool(element.text or "")
    except ValueError:
        raise document.fail(element, f"<{element.tag}> must be true, false, 1 or 0, "
                                     f"got '{(element.text or '').strip()}'") from None


def read_bool_attribute(element: ET.Element, name: str) -> bool:
    return element.get(name, "").strip().lower() in _TRUE


def read_attribute_numbers(element: ET.Element, attribute: str, document: XmlDocument,
                           default: Sequence[float], count: int = 3) -> Tuple[float, ...]:
    """URDF style: ``<origin xyz="0 0 1"/>``; an absent attribute is ``default``."""
    text = element.get(attribute)
    if text is None:
        return tuple(default)
    try:
        return parse_floats(text, count)
    except ValueError as problem:
        raise document.fail(element, f"<{element.tag} {attribute}>: {problem}") from None


def read_origin(parent: ET.Element, document: XmlDocument) -> Pose:
    """URDF ``<origin xyz rpy>`` below ``parent``; absent is the identity."""
    origin = parent.find("origin")
    if origin is None:
        return IDENTITY
    xyz = read_attribute_numbers(origin, "xyz", document, (0.0, 0.0, 0.0))
    _check_offset(xyz, document, origin, "<origin xyz>")
    return pose_from_xyz_rpy(xyz, read_attribute_numbers(origin, "rpy", document, (0.0, 0.0, 0.0)))
