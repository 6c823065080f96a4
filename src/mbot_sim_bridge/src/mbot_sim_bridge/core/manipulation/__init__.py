"""The plugins that push and hold things: a wrench topic on a link (force), the vacuum gripper."""
from ..errors import ConfigError


def body_link(plugin) -> str:
    """The ``bodyName`` link, which must be one the physics keeps (not lumped by a fixed joint), as upstream's
    Model::GetLink finds it; else the spawn is refused naming the links there are."""
    link = plugin.params["bodyName"]
    links = plugin.context.robot.link_index
    if link not in links:
        raise ConfigError(f"{plugin.context.where(plugin.element)}: {plugin.label}: bodyName: link named: {link} "
                          f"does not exist in model '{plugin.context.model.name}' (it must not hang on a fixed "
                          f"joint; links there are: {', '.join(sorted(links))})")
    return link
