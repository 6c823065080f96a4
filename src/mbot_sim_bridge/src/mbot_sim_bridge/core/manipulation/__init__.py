"""The plugins that push and hold things: a wrench topic on a link (force), the vacuum gripper."""
