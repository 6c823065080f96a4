"""dynamic_reconfigure's messages (generated) and a Python server for a flat list of parameters (server.py)."""
