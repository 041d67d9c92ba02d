# Copyright 2026 orca_ros developers
#
# Licensed under the Apache License, Version 2.0 (the "License");
# you may not use this file except in compliance with the License.
# You may obtain a copy of the License at
#
#     http://www.apache.org/licenses/LICENSE-2.0
#
# Unless required by applicable law or agreed to in writing, software
# distributed under the License is distributed on an "AS IS" BASIS,
# WITHOUT WARRANTIES OR CONDITIONS OF ANY KIND, either express or implied.
# See the License for the specific language governing permissions and
# limitations under the License.
"""
Which self-collision pairs to watch, chosen as MoveIt's setup assistant chooses them.

A robot's own pairs fall into four kinds the collision constraint must not watch, by link:

* ``adjacent``: two links on one rigid body or on bodies joined by a joint (Pinocchio merges the
  links of fixed joints into their body, so a link fixed to the wrist is adjacent to the forearm
  the wrist turns on); left out when the pairs are made (:class:`.collision_geometry.
  CollisionGeometry`);
* ``default``: in contact at the default posture (the neutral configuration, a joint whose limits
  exclude it at their middle) or at the start posture: parts that touch by design, or a start
  the constraint cannot honour;
* ``always``: in contact in at least :data:`ALWAYS` of the sampled postures;
* ``near``: within the constraint's safety distance in at least :data:`ALWAYS` of the sampled
  postures (not in contact): the kinematics hold the links that close, the constraint could only
  hold the robot still where it finds them (an iiwa's link 5 and flange link 7 hulls, closer
  than a 3 cm safety distance in nearly every posture: watched there, the pair's row asked for
  separations its joints' velocity limits did not allow, and every cycle failed);
* ``never``: in contact in none of the sampled postures: the kinematics keep the links apart (a
  UR5's tool flange block and its first wrist link are 2-3 cm apart and cannot meet; watched, the
  pair held the wrist still from the start).

Contact is judged on the constraint's own geometry (convex hulls inflated by its rounding) for
the sampled kinds, so a pair left out as ``never`` keeps at least twice the rounding between its
meshes' hulls in every sample; at the default and start postures on the hulls themselves (a pair
merely closer than the rounding there stays watched: the constraint keeps it from closing
further, :mod:`orca_ros.constraint.collision_avoidance`). The postures are uniform within the
joint limits (unbounded angles within [-pi, pi]), seeded: the same robot gives the same pairs.
``disabled`` (an SRDF's ``disable_collisions``) comes first and is not sampled again.

Sampling :data:`SAMPLES` postures takes a second or more; per link pair, the share of the samples
in contact and the distance within which :data:`ALWAYS` of them lie are kept in a cache
file per robot geometry (``$XDG_CACHE_HOME/orca_ros`` or ``~/.cache/orca_ros``), keyed by the
geometry's shapes, placements, joints, limits and the sampling's settings. :func:`srdf_text`
writes the left-out pairs as an SRDF for the user to review and pass as ``srdf`` (``python -m
orca_ros.robot.collision_pairs URDF``).
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import sys

import numpy as np
import pinocchio as pin

#: postures sampled (MoveIt's default sampling density)
SAMPLES = 10000
#: a pair in contact in at least this share of the samples is always in contact (MoveIt's)
ALWAYS = 0.95
_SEED = 0
_VERSION = 2  # of the cache files' content


def link_of(model, geometry) -> str:
    """Return the link (frame) a geometry of the robot belongs to."""
    return model.frames[geometry.parentFrame].name


def link_pair(model, gm, pair) -> tuple[str, str]:
    """Return the links of a geometry pair of ``gm``, in the pair's order."""
    objects = gm.geometryObjects
    return link_of(model, objects[pair.first]), link_of(model, objects[pair.second])


def _limits(model) -> tuple[np.ndarray, np.ndarray]:
    """Return the sampling bounds: the limits, unbounded coordinates within [-pi, pi]."""
    lo, hi = model.lowerPositionLimit.copy(), model.upperPositionLimit.copy()
    with np.errstate(over='ignore', invalid='ignore'):  # (limits of +-DBL_MAX: unbounded)
        width = hi - lo
    wide = ~np.isfinite(width) | (width > 2.0 * np.pi)
    lo[wide], hi[wide] = -np.pi, np.pi
    return lo, hi


def default_posture(model) -> np.ndarray:
    """Return the neutral configuration, a coordinate outside its limits at their middle."""
    q = pin.neutral(model)
    lo, hi = model.lowerPositionLimit, model.upperPositionLimit
    for j in range(1, model.njoints):
        joint = model.joints[j]
        if joint.nq == joint.nv == 1:  # revolute and prismatic (as MoveIt's default values)
            i = joint.idx_q
            if not lo[i] <= q[i] <= hi[i]:
                q[i] = 0.5 * (lo[i] + hi[i])
    return q


def _rounding(gm, g: int) -> float:
    return float(gm.geometryObjects[g].geometry.getSweptSphereRadius())


def _contacts(model, data, gm, gd, q) -> np.ndarray:
    """Return, per geometry pair of ``gm``, whether it is in contact at ``q``."""
    pin.computeCollisions(model, data, gm, gd, q, False)
    return np.fromiter((r.isCollision() for r in gd.collisionResults), dtype=bool,
                       count=len(gm.collisionPairs))


def _distances(model, data, gm, gd, q) -> np.ndarray:
    """Return, per geometry pair of ``gm``, its distance at ``q`` (< 0: in contact, by as much)."""
    pin.computeDistances(model, data, gm, gd, q)
    return np.fromiter((r.min_distance for r in gd.distanceResults), dtype=float,
                       count=len(gm.collisionPairs))


def _key(model, gm, samples: int, seed: int) -> str:
    """Return a digest of what the sampled kinds depend on (the cache file's name)."""
    h = hashlib.sha256()
    h.update(repr((_VERSION, samples, seed, ALWAYS, model.nq, list(model.parents),
                   [str(j.shortname()) for j in model.joints])).encode())
    for a in (model.lowerPositionLimit, model.upperPositionLimit):
        h.update(np.ascontiguousarray(a).tobytes())
    for j in range(model.njoints):
        h.update(np.asarray(model.jointPlacements[j].homogeneous).tobytes())
    for g in gm.geometryObjects:
        h.update(f'{g.name} {g.parentJoint} {type(g.geometry).__name__}'.encode())
        h.update(np.asarray(g.placement.homogeneous).tobytes())
        geometry = g.geometry
        h.update(repr(getattr(geometry, 'getSweptSphereRadius', lambda: 0.0)()).encode())
        points = geometry.points() if hasattr(geometry, 'points') else None
        if points is not None:
            h.update(np.ascontiguousarray(np.asarray(points)).tobytes())
        for attr in ('radius', 'halfLength', 'halfSide'):
            if hasattr(geometry, attr):
                h.update(np.asarray(getattr(geometry, attr), dtype=float).tobytes())
    for p in gm.collisionPairs:
        h.update(f'{p.first},{p.second};'.encode())
    return h.hexdigest()[:32]


def _cache_dir() -> str:
    base = os.environ.get('XDG_CACHE_HOME') or os.path.join(os.path.expanduser('~'), '.cache')
    return os.path.join(base, 'orca_ros', 'collision_pairs')


def sampled(model, gm, samples: int = SAMPLES, seed: int = _SEED,
            cache: bool = True) -> dict[tuple[str, str], tuple[float, float]]:
    """
    Return {(link, link): (share in contact, distance)} over the pairs of ``gm``, by link.

    A link pair's distance in a sample is the least of its geometry pairs'; ``share``: of the
    samples where it is <= 0; ``distance``: the one :data:`ALWAYS` of the samples are within.
    From the cache file when one matches (see the module), else sampled and written there (best
    effort).
    """
    path = os.path.join(_cache_dir(), _key(model, gm, samples, seed) + '.json') if cache else None
    if path is not None and os.path.isfile(path):
        try:
            with open(path) as fh:
                return {tuple(k.split('\n')): tuple(v) for k, v in json.load(fh).items()}
        except (OSError, ValueError, TypeError):
            pass
    links = [link_pair(model, gm, p) for p in gm.collisionPairs]
    names = sorted(set(links))
    index = np.array([names.index(pair) for pair in links], dtype=int)
    least = np.full((samples, len(names)), np.inf)
    data, gd = model.createData(), pin.GeometryData(gm)
    lo, hi = _limits(model)
    pin.seed(seed)
    for k in range(samples):
        d = _distances(model, data, gm, gd, pin.randomConfiguration(model, lo, hi))
        np.minimum.at(least[k], index, d)
    out = {}
    if samples > 0:
        share = (least <= 0.0).mean(axis=0)
        within = np.quantile(least, ALWAYS, axis=0)
        out = {pair: (float(a), float(b)) for pair, a, b in zip(names, share, within)}
    if path is not None:
        try:
            os.makedirs(os.path.dirname(path), exist_ok=True)
            tmp = f'{path}.{os.getpid()}'
            with open(tmp, 'w') as fh:
                json.dump({'\n'.join(k): v for k, v in out.items()}, fh)
            os.replace(tmp, path)
        except OSError:
            pass
    return out


def sampled_kinds(model, gm, samples: int = SAMPLES, seed: int = _SEED, cache: bool = True,
                  near: float = 0.0) -> dict[tuple[str, str], str]:
    """
    Return {(link, link): 'always' | 'near' | 'never'} over the pairs of ``gm``, by link.

    ``near``: the safety distance (0: no pair is ``near``). See the module and :func:`sampled`.
    """
    kinds = {}
    for pair, (share, within) in sampled(model, gm, samples, seed, cache).items():
        if share == 0.0:
            kinds[pair] = 'never'
        elif share >= ALWAYS:
            kinds[pair] = 'always'
        elif within < near:
            kinds[pair] = 'near'
    return kinds


def left_out(model, gm, postures=(), samples: int = SAMPLES, seed: int = _SEED,
             cache: bool = True, near: float = 0.0) -> dict[tuple[str, str], str]:
    """
    Return the link pairs of ``gm`` not to watch, with their reason (see the module).

    ``postures``: configurations whose contacts are ``default`` (the default posture is always
    one); ``samples`` 0 samples nothing (only the postures' contacts are left out); ``near``:
    the safety distance the ``near`` kind is judged by (0: none).
    """
    out = {}
    data, gd = model.createData(), pin.GeometryData(gm)
    for k, p in enumerate(gm.collisionPairs):  # touching: the hulls themselves, not rounded
        gd.collisionRequests[k].security_margin = -(_rounding(gm, p.first)
                                                    + _rounding(gm, p.second))
    for q in (default_posture(model), *postures):
        touching = _contacts(model, data, gm, gd, np.asarray(q, dtype=float))
        for k in np.flatnonzero(touching).tolist():
            out.setdefault(link_pair(model, gm, gm.collisionPairs[k]), 'default')
    if samples > 0:
        for pair, kind in sampled_kinds(model, gm, samples, seed, cache, near).items():
            out.setdefault(pair, kind)
    return out


def remove_pairs(model, gm, pairs) -> None:
    """Remove from ``gm`` every geometry pair of the given link pairs (either order)."""
    gone = {frozenset(p) for p in pairs}
    doomed = [(p.first, p.second) for p in gm.collisionPairs   # (copied first: the pairs
              if frozenset(link_pair(model, gm, p)) in gone]       # shift as some are removed)
    for first, second in doomed:
        gm.removeCollisionPair(pin.CollisionPair(first, second))


def summary(left: dict[tuple[str, str], str], kept: int) -> str:
    """Return one line: how many pairs are watched, how many left out and why, which."""
    if not left:
        return f'{kept} link pairs watched, none left out'
    by = {}
    for (a, b), why in sorted(left.items()):
        by.setdefault(why, []).append(f'{a}/{b}')
    told = '; '.join(f"{why} ({len(p)}): {', '.join(p)}" for why, p in sorted(by.items()))
    return f'{kept} link pairs watched, {len(left)} left out: {told}'


def srdf_text(robot_name: str, left: dict[tuple[str, str], str]) -> str:
    """Return an SRDF whose ``disable_collisions`` are ``left`` (reasons as MoveIt writes them)."""
    reason = {'never': 'Never', 'always': 'Always', 'near': 'Always', 'default': 'Default',
              'adjacent': 'Adjacent', 'disabled': 'User'}
    lines = ['<?xml version="1.0"?>', f'<robot name="{robot_name}">']
    for (a, b), why in sorted(left.items()):
        lines.append(f'  <disable_collisions link1="{a}" link2="{b}" '
                     f'reason="{reason.get(why, why)}"/>')
    lines.append('</robot>')
    return '\n'.join(lines) + '\n'


def main(argv=None) -> int:
    """Write the pairs a URDF's collision constraint leaves out as an SRDF (stdout or -o)."""
    from .collision_geometry import CollisionGeometry  # noqa: PLC0415
    from .robot_model import RobotModel  # noqa: PLC0415

    ap = argparse.ArgumentParser(prog='python -m orca_ros.robot.collision_pairs',
                                 description=main.__doc__)
    ap.add_argument('urdf')
    ap.add_argument('--srdf', help="an SRDF whose disable_collisions are kept (as 'User')")
    ap.add_argument('--samples', type=int, default=SAMPLES)
    ap.add_argument('--safety-distance', type=float, default=0.0,
                    help="the constraint's: pairs within it in 95 %% of the postures left out")
    ap.add_argument('-o', '--output', help='the SRDF to write (default: stdout)')
    args = ap.parse_args(argv)
    robot = RobotModel()
    robot.load_model_from_file(args.urdf)
    geometry = CollisionGeometry(robot, args.srdf, samples=args.samples,
                                 near=args.safety_distance)
    text = srdf_text(robot.model.name, geometry.left_out)
    print(geometry.pair_summary, file=sys.stderr)
    if args.output:
        with open(args.output, 'w') as fh:
            fh.write(text)
    else:
        sys.stdout.write(text)
    return 0


if __name__ == '__main__':
    sys.exit(main())
