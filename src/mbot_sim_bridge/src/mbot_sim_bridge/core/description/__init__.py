"""What is simulated, read from its files: the URDF, .world and SDF files, model paths, meshes and materials, and
the running world written back as SDF."""
