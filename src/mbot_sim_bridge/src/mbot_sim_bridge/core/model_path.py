"""Where ``model://NAME`` is looked up, in Gazebo's order.

GAZEBO_MODEL_PATH comes first, then this workspace's ``worlds/models``. A model directory is one that holds a
``model.config`` (or the deprecated ``manifest.xml``).
"""
import os
from pathlib import Path
from typing import List, Optional, Sequence

MODEL_MANIFESTS = ("model.config", "manifest.xml")


def default_model_path() -> List[str]:
    """Directories searched for ``model://NAME``: GAZEBO_MODEL_PATH, then this workspace's worlds/models."""
    directories = [entry for entry in os.environ.get("GAZEBO_MODEL_PATH", "").split(":") if entry]
    workspace_models = _workspace_models()
    if workspace_models:
        directories.append(workspace_models)
    return directories


def _workspace_models() -> Optional[str]:
    # The real path leads back to the source tree from a source checkout and from catkin's devel space
    # (its generated package __init__ extends __path__ to the sources). An install space has no repo root,
    # so ROS_PACKAGE_PATH is tried for mbot_gazebo, whose worlds/ links to the same folder.
    module = Path(os.path.realpath(__file__))  # <repo>/src/mbot_sim_bridge/src/mbot_sim_bridge/core/model_path.py
    candidates = [module.parents[5] / "worlds" / "models"] if len(module.parents) > 5 else []
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
