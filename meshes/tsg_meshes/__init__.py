"""ConsiGma-1 twin-screw granulator meshes for LIGGGHTS: screw configurations (spec) -> screw and
barrel STL surfaces and a zones file. CLI: python -m tsg_meshes; usage and grammar: meshes/README.md."""
