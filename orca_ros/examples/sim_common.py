"""Shared pieces of the simulator examples (the reference's Gazebo examples, on PyBullet)."""
from __future__ import annotations

import argparse

from .. import Logger, default_urdf_path


def parse_sim_args(description: str, argv=None, extra=None):
    rest = Logger.parse_argv(argv)
    p = argparse.ArgumentParser(description=description)
    p.add_argument("urdf", nargs="?", default=None, help="robot URDF (default: the shipped lwr.urdf)")
    p.add_argument("--gui", action="store_true", help="show the PyBullet window")
    p.add_argument("--duration", type=float, default=2.0, help="simulated seconds")
    if extra is not None:
        extra(p)
    args = p.parse_args(rest)
    args.urdf = args.urdf or default_urdf_path()
    return args
