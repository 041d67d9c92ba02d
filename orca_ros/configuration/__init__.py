"""Controller set-up from configuration dictionaries (YAML), without ROS."""
from .controller_builder import ConfigError, ControllerSetup, build_from_config, resolve_urdf_path

__all__ = ["ConfigError", "ControllerSetup", "build_from_config", "resolve_urdf_path"]
