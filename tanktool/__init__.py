"""tanktool: arena-authoring pipeline and runtime for a 3D tank-combat game."""

__version__ = "0.1.0"
