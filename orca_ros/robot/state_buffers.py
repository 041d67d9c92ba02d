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
The state a :class:`~orca_ros.robot.robot_model.RobotModel` holds for its current cycle.

What Pinocchio's ``Data`` is to its ``Model``: buffers sized once for the model, written by the
state input (:mod:`.state_input`, or the compiled cycle's kernel,
:mod:`.state_input_kernel`) and read by the algorithms of the cycle. Readers
outside the robot package treat them as read-only views valid until the next state change.

* ``q_pin`` (nq), ``v_pin`` (nv): the state in Pinocchio's convention (a floating base: position,
  unit quaternion x y z w, then the joints; its twist in the base frame, then the joints);
* ``q``, ``v`` (ndof): the joints alone, in the model's joint order (a continuous joint's angle,
  where Pinocchio holds cos and sin);
* ``world_H_base`` (4x4), ``base_twist_world`` (6, [linear; angular] in world axes): the floating
  base as odometry gives it; derived from ``q_pin``, ``v_pin`` only when asked where
  ``base_from_q_pin`` is set (a state given in Pinocchio's convention);
* ``gravity`` (3): the model's gravity vector;
* ``stamp``: incremented at every change of the state or gravity (caches compare against it);
  ``terms_stamp``: the stamp of Pinocchio's last ``computeAllTerms`` in the robot's Data;
  ``initialized``: a state was given;
* ``q_map``: (index in q_pin, nq) per joint, ``q_simple`` when every joint's nq is 1 (then q is
  q_pin's tail);
* ``state_kernel``: the compiled state input a compiled cycle gives (None: Python's), and
  ``com``, ``centroidal``: the centre of mass's and the centroidal momentum's terms, made on
  first use. All three are made again with a new model (a re-weld of locked joints).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin


class StateBuffers:
    """The robot's state for one model (see the module)."""

    __slots__ = ('q_pin', 'v_pin', 'q', 'v', 'world_H_base', 'base_twist_world',
                 'base_from_q_pin', 'gravity', 'stamp', 'terms_stamp', 'initialized', 'q_map',
                 'q_simple', 'state_kernel', 'com', 'centroidal')

    def __init__(self, model: pin.Model, joint_ids, ndof: int):
        self.q_map, self.q_simple = [], True
        for j in joint_ids:
            jm = model.joints[j]
            if jm.nq == jm.nv == 1:
                self.q_map.append((jm.idx_q, 1))
            elif jm.nq == 2 and jm.nv == 1:
                self.q_map.append((jm.idx_q, 2))
                self.q_simple = False
            else:
                raise ValueError(
                    f"joint '{model.names[j]}' of type {jm.shortname()} is not supported "
                    '(only 1-DoF revolute/prismatic/continuous joints)'
                )
        self.q_pin = pin.neutral(model)
        self.v_pin = np.zeros(model.nv)
        self.q = np.zeros(ndof)
        self.v = np.zeros(ndof)
        self.world_H_base = np.eye(4)
        self.base_twist_world = np.zeros(6)
        self.base_from_q_pin = False
        self.gravity = np.array([0.0, 0.0, -9.81])
        self.stamp = 0
        self.terms_stamp = -1
        self.initialized = False
        self.renew_caches()

    def renew_caches(self) -> None:
        """Drop what was made for the last model (the state kernel, CoM and momentum terms)."""
        self.state_kernel = None
        self.com = None
        self.centroidal = None
