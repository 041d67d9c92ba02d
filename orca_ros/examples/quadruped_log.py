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
The log of a quadruped run in PyBullet.

Tracking, foot slip, contact forces against their cones and bounds, torques, and how well the
solution satisfies the equation of motion.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass
class RunLog:
    t: list = field(default_factory=list)
    base: list = field(default_factory=list)
    base_target: list = field(default_factory=list)
    feet: list = field(default_factory=list)  # PyBullet foot (sphere centre) positions (4, 3)
    slip: list = field(
        default_factory=list
    )  # PyBullet tangential velocity of the foot's lowest point (4, 2)
    forces: list = field(default_factory=list)  # solution contact forces (4, 3)
    bounds: list = field(default_factory=list)  # normal-force upper bounds (4,)
    cone: list = field(default_factory=list)  # max over faces of d_k.f - mu_eff n.f (4,)
    tau: list = field(default_factory=list)
    loaded: list = field(default_factory=list)  # contact fully on (activated) (4,)
    dynamics: list = field(
        default_factory=list
    )  # max |M nu_dot + n - S^T tau - J_c^T w| of the solution
    failures: int = 0

    def arrays(self):
        return {k: np.array(v) for k, v in self.__dict__.items() if isinstance(v, list)}


def record_step(log, qc, sim_model, t, target, foot_radius: float) -> None:
    """Append this step's measurements of the controller ``qc`` (QuadrupedController) to log."""
    robot = qc.robot
    legs = list(qc.contacts)
    log.t.append(t)
    log.base.append(robot.get_world_to_base_transform()[:3, 3].copy())
    log.base_target.append(np.array(target))
    feet = getattr(qc, 'feet', {leg: f'{leg}_foot' for leg in legs})
    log.feet.append(np.array([sim_model.get_link_position(feet[leg]) for leg in legs]))
    slip = []
    for leg in legs:  # the sphere's material point touching the ground moves at v_c + w x (-r z)
        lin, ang = sim_model.get_link_velocity(feet[leg])
        slip.append((lin + np.cross(ang, [0.0, 0.0, -foot_radius]))[:2])
    log.slip.append(slip)
    F = qc.contact_forces()
    log.forces.append(F)
    log.bounds.append([qc.contacts[leg].normal_force_bound() for leg in legs])
    log.cone.append([np.max(qc.contacts[leg].faces @ F[i]) for i, leg in enumerate(legs)])
    log.tau.append(qc.controller.get_joint_torque_command())
    log.loaded.append([qc.contacts[leg].is_activated() for leg in legs])
    log.dynamics.append(dynamics_residual(qc.controller))


def dynamics_residual(controller) -> float:
    """Largest violation of the equation of motion by the controller's full solution."""
    robot, lay = controller.robot, controller.layout
    sol = controller.get_solution()
    nv, nb = lay.nv, lay.nbase
    acc, tau, w = sol[:nv], sol[nv + nb: nv + nv], sol[nv + nv:]
    lhs = robot.get_mass_matrix() @ acc + robot.get_generalized_gravity_and_coriolis_torques()
    rhs = np.concatenate((np.zeros(nb), tau)) + lay.wrench_jacobian.T @ w
    return float(np.max(np.abs(lhs - rhs)))
