"""Where ``model://NAME`` and world files are looked up, in Gazebo's order.

Models: GAZEBO_MODEL_PATH comes first, then the ``gazebo_model_path`` that packages export in their package.xml
(``<export><gazebo_ros gazebo_model_path="${prefix}/models"/></export>``, as gazebo_ros's paths plugin adds
them), then this workspace's ``worlds/models``. A model directory is one that holds a ``model.config`` (or the
deprecated ``manifest.xml``). Resources (world files, ``file://`` URIs): GAZEBO_RESOURCE_PATH, then the
exported ``gazebo_media_path``, then the workspace folder that holds ``worlds/empty.world`` (as Gazebo's own
share folder does, so gazebo_ros's default ``worlds/empty.world`` resolves).

The exports come from the caller (``gazebo_paths.py`` in the ROS layer asks rospack for them), so the core
runs no ROS tool.
"""
import os
from pathlib import Path
from typing import List, Optional, Sequence

MODEL_MANIFESTS = ("model.config", "manifest.xml")


def default_model_path(exported: Sequence[str] = ()) -> List[str]:
    """Directories searched for ``model://NAME``: GAZEBO_MODEL_PATH, the packages' gazebo_model_path
    exports (``exported``), then this workspace's worlds/models."""
    directories = _environment_path("GAZEBO_MODEL_PATH") + list(exported)
    workspace_models = _workspace_models()
    if workspace_models:
        directories.append(workspace_models)
    return _unique(directories)


def default_resource_path(exported: Sequence[str] = ()) -> List[str]:
    """Directories world files and ``file://`` URIs are relative to: GAZEBO_RESOURCE_PATH, the packages'
    gazebo_media_path exports (``exported``), then the workspace folder holding worlds/."""
    directories = _environment_path("GAZEBO_RESOURCE_PATH") + list(exported)
    workspace_models = _workspace_models()
    if workspace_models:
        directories.append(os.path.dirname(os.path.dirname(workspace_models)))
    return _unique(directories)


def find_world_file(name: str, resource_path: Sequence[str]) -> Optional[str]:
    """``name`` as an existing file (absolute or relative to the current directory), else the first
    ``resource_path`` directory holding it, as gzserver resolves its world argument; None if none does."""
    if os.path.isfile(name):
        return os.path.abspath(name)
    if os.path.isabs(name):
        return None
    return next((os.path.join(directory, name) for directory in resource_path
                 if os.path.isfile(os.path.join(directory, name))), None)


def _environment_path(variable: str) -> List[str]:
    return [entry for entry in os.environ.get(variable, "").split(":") if entry]


def _unique(directories: Sequence[str]) -> List[str]:
    # A folder named twice (GAZEBO_MODEL_PATH and an export) is searched once, at its first place.
    return list(dict.fromkeys(directories))


def _workspace_models() -> Optional[str]:
    # The real path leads back to the source tree from a source checkout and from catkin's devel space
    # (its generated package __init__ extends __path__ to the sources). An install space has no repo root,
    # so ROS_PACKAGE_PATH is tried for mbot_gazebo, whose worlds/ links to the same folder.
    module = Path(os.path.realpath(__file__))  # <repo>/src/mbot_sim_bridge/src/mbot_sim_bridge/core/description/
    candidates = [module.parents[6] / "worlds" / "models"] if len(module.parents) > 6 else []
    candidates += [Path(entry) / "mbot_gazebo" / "worlds" / "models"
                   for entry in os.environ.get("ROS_PACKAGE_PATH", "").split(":") if entry]
    return next((str(candidate) for candidate in candidates if candidate.is_dir()), None)


def find_model_directory(name: str, model_path: Sequence[str]) -> Optional[str]:
    """The first directory on ``model_path`` that holds model ``name``."""
    for directory in model_path:
        candidate = os.path.join(directory, name)
        if any(os.path.isfile(os.path.join(candidate, manifest)) for manifest in MODEL_MANIFESTS):
            return candidate
    return None
