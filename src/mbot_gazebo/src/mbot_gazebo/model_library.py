"""The models that can be inserted by name (Gazebo's Insert tab): every model directory on the model path.

The model path is the bridge's (GAZEBO_MODEL_PATH, this workspace's worlds/models, and what packages
export), searched in order: a name found twice is the first one, as ``model://NAME`` resolves it.
"""
import difflib
import os
import xml.etree.ElementTree as ET
from typing import List, NamedTuple, Optional, Sequence

from mbot_sim_bridge.core.description.model_path import MODEL_MANIFESTS
from mbot_sim_bridge.gazebo_paths import model_path as exported_model_path

# Gazebo ships these and so does the bridge (core.description.sdf_world.BUILTIN_MODEL_NAMES, checked by a test; not
# imported because it brings in PyBullet, which prints its build time); a model of the same name on the path wins.
BUILTIN_MODELS = {"ground_plane": "Gazebo's ground plane: a static 100 x 100 m plane (built in)",
                  "sun": "Gazebo's directional light (built in; not simulated, kept when a world is saved)"}


class LibraryModel(NamedTuple):
    name: str  # the directory name: what model://NAME and spawn_model -database NAME use
    title: str  # model.config <name>
    description: str  # model.config <description>, whitespace collapsed
    path: str  # the model directory


class UnknownModel(LookupError):
    pass


def list_models(model_path: Optional[Sequence[str]] = None) -> List[LibraryModel]:
    """Every model on ``model_path`` (default: the bridge's), sorted by name; the first of a name wins."""
    found = {}
    for directory in exported_model_path() if model_path is None else model_path:
        if not os.path.isdir(directory):
            continue
        for name in sorted(os.listdir(directory)):
            if name in found:
                continue
            model_directory = os.path.join(directory, name)
            manifest = next((os.path.join(model_directory, manifest) for manifest in MODEL_MANIFESTS
                             if os.path.isfile(os.path.join(model_directory, manifest))), None)
            if manifest is not None:
                found[name] = _read_manifest(name, model_directory, manifest)
    for name, description in BUILTIN_MODELS.items():
        found.setdefault(name, LibraryModel(name, name, description, "(built in)"))
    return [found[name] for name in sorted(found)]


def _read_manifest(name: str, directory: str, manifest: str) -> LibraryModel:
    try:
        root = ET.parse(manifest).getroot()
    except ET.ParseError as error:
        return LibraryModel(name, name, f"(unreadable {os.path.basename(manifest)}: {error})", directory)
    title = " ".join((root.findtext("name") or name).split())
    description = " ".join((root.findtext("description") or "").split())
    return LibraryModel(name, title, description, directory)


def find_model(name: str, models: Sequence[LibraryModel]) -> LibraryModel:
    """The model called ``name``; UnknownModel names the nearest ones when there is none."""
    for model in models:
        if model.name == name:
            return model
    names = [model.name for model in models]
    nearest = difflib.get_close_matches(name, names, n=5, cutoff=0.5)
    hint = f"; nearest: {', '.join(nearest)}" if nearest else ""
    raise UnknownModel(f"no model '{name}' on the model path{hint} (./mbot models lists all {len(names)})")


def instance_name(name: str, existing: Sequence[str]) -> str:
    """Gazebo's names for inserted models: NAME the first time, then NAME_0, NAME_1, ..."""
    if name not in existing:
        return name
    index = 0
    while f"{name}_{index}" in existing:
        index += 1
    return f"{name}_{index}"


def format_table(models: Sequence[LibraryModel]) -> str:
    """Per model, its name and description (the title when there is none), then its path on a line below."""
    width = max((len(model.name) for model in models), default=0)
    lines = []
    for model in models:
        lines.append(f"{model.name:<{width}}  {model.description or model.title}")
        lines.append(f"{'':<{width}}  {model.path}")
    return "\n".join(lines)
