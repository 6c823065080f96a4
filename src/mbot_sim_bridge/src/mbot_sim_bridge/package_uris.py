"""package:// URIs in robot descriptions, resolved with rospkg as spawn_urdf_model resolves them (PyBullet
knows no packages): for spawning, and for the descriptions gazebo_ros_control reads from the parameter server."""
import re

import rospkg

from .core.errors import ModelError


def resolve_package_uris(xml: str) -> str:
    """package://pkg/ -> the package's absolute path, as spawn_urdf_model does (PyBullet knows no packages)."""
    packages = rospkg.RosPack()

    def replace(match):
        try:
            return packages.get_path(match.group(1)) + "/"
        except rospkg.ResourceNotFound:
            raise ModelError(f"package://{match.group(1)}/ in the model: no such package") from None
    # Only a package name (letters, digits, '_', '-', '.') counts: gazebo_ros takes whatever precedes the next '/',
    # so a "package:// ..." in an XML comment refused the whole model with a garbled name.
    return re.sub(r"package://([\w.-]+)/", replace, xml)
