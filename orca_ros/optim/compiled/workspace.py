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
The cycle's arrays in one numba structure, so that a kernel call passes one argument.

numba unboxes every array argument of a call, each at a cost; the cycle has dozens of arrays.
A StructRef holds references to them (no copy: Pinocchio's live views, the plan's
arrays, the lowering's tables) and passes as one pointer; its kernels are cached on disk like
the others. Made once per configuration.
"""

from __future__ import annotations

from numba.experimental import structref

from ...utils.jit import njit
from ...utils.struct_type import StructType

#: the fields, in order (see CompiledCycle for what each is)
FIELDS = (
    # Pinocchio's Data and the robot's state; the accelerations with gravity, gravity, and
    # whether the drifts aj are to be derived from them this cycle (robot/terms_kernel.py)
    'J', 'oMi', 'vj', 'aj', 'q', 'v', 'v_pin', 'T', 't0', 'a_gf', 'grav', 'derive',
    # the plan: dense task rows, diagonal tasks, level 0's problem, constraints, joint boxes
    'E', 'f', 'w', 'sel', 'row_task', 'ew',
    'dg_f', 'dg_sel', 'dg_colw', 'dg_ws', 'dg_wsf', 'dg_tab', 'dg_ew',
    'H', 'g', 'WE', 'M', 'lo', 'hi', 'con_tab', 'con_on', 'box_lb', 'box_ub', 'box_on',
    # the lowered objects' records and table
    'cart', 'cart_sup', 'jrec', 'lims', 'pacc', 'tab', 'par', 'tmp',
    # the centre of mass (Data's com[0], vcom[0], Jcom), the bodies' [mass, lever] (row 0: the
    # total mass) and the CoM tasks' records; the centroidal momentum's map, value and drift
    # (the robot's CentroidalMomentum terms) and the momentum tasks' records
    'com', 'vcom', 'Jcom', 'body', 'crec', 'Ag', 'hg', 'dhg', 'mrec',
    # the contacts (constraint/contact_kernel.py): Pinocchio's M and nle, the wrench Jacobians, the
    # contacts' table, parameters and soles' faces, the dynamics rows [first row in M, on]
    'M_pin', 'nle', 'Wj', 'ct_tab', 'ct_par', 'ct_faces', 'ct_sup', 'dyn',
    # every contact's wrench: its first variable, its last solved wrench, how many contacts
    'ct_ws', 'ct_last', 'n_wrenches',
    # sizes: nx, n_eq, level 0's dense rows and diagonal tasks, soft boxes, first joint, joints
    'nx', 'ne', 'n0', 'nd0', 'nsoft', 'jb', 'nj',
)


@structref.register
class CycleWorkspaceType(StructType):
    """Its fields' types: see struct_type."""


class CycleWorkspace(structref.StructRefProxy):
    """The arrays of one compiled cycle (fields: :data:`FIELDS`)."""


structref.define_proxy(CycleWorkspace, CycleWorkspaceType, list(FIELDS))


@njit
def _construct(*fields):
    """Make the workspace in compiled code: cached on disk, unlike the proxy's own constructor."""
    return CycleWorkspace(*fields)


def make_workspace(**arrays) -> CycleWorkspace:
    missing = set(FIELDS) - set(arrays)
    if missing:
        raise TypeError(f'workspace fields missing: {sorted(missing)}')
    # (CycleWorkspace(...) in Python compiles numba's constructor anew in every process: most
    # of a warm start's time)
    return _construct(*(arrays[name] for name in FIELDS))
