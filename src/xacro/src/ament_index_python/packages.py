"""``get_package_share_directory`` for xacro's ``$(find pkg)``, over ROS 1's package path (see the package doc)."""
import rospkg


class PackageNotFoundError(KeyError):
    """As ament's: the package is not on the package path."""


def get_package_share_directory(package_name: str) -> str:
    """A ROS 1 package's folder (where ``$(find pkg)`` points in ROS 1)."""
    try:
        return rospkg.RosPack().get_path(package_name)
    except rospkg.ResourceNotFound:
        raise PackageNotFoundError(f"package '{package_name}' not found on ROS_PACKAGE_PATH") from None
