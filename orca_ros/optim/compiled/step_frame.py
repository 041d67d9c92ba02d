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
The one-call cycle's arguments in one numba structure: a call passes it and the cycle's time.

A call into compiled code unboxes every argument, each at a cost: :func:`.cycle_kernel.step`'s
thirteen (two structures, five arrays, six scalars) cost several times what a structure and two
scalars do in the control loop. The frame holds what stays from cycle to cycle
(the workspace, DAQP's state, the time model, the controller's output arrays, the clock, the
iteration floor, whether the kernel writes the solution out); made when the one-call cycle is
bound (:class:`.fused_step.FusedStep`), again when any of them is replaced.
"""

from __future__ import annotations

from numba.experimental import structref

from .cycle_kernel import finish, step
from ...utils.jit import njit
from ...utils.struct_type import StructType

#: the fields, in order (see cycle_kernel.step for what each is)
FIELDS = ('ws', 's', 'timing', 'x_out', 'acc_out', 'tau', 'tau_cmd', 'clock', 'least', 'out')


@structref.register
class StepFrameType(StructType):
    """Its fields' types: see struct_type."""


class StepFrame(structref.StructRefProxy):
    """What the one-call cycle's kernel reads besides the cycle's time (fields: :data:`FIELDS`)."""


structref.define_proxy(StepFrame, StepFrameType, list(FIELDS))


@njit
def _construct(*fields):
    """Make the frame in compiled code: cached on disk, unlike the proxy's own constructor."""
    return StepFrame(*fields)


def make_frame(ws, s, timing, outs, clock: int, least: int, out: int) -> StepFrame:
    """Return the frame of a workspace, DAQP's state, the time model and the outputs."""
    return _construct(ws, s, timing, *outs, clock, least, out)


@njit
def framed_step(fr, dt, deadline, most):
    """:func:`.cycle_kernel.step` with the frame's arguments: ``most`` iterations at most."""
    return step(fr.ws, fr.s, dt, deadline, most, fr.least, fr.timing, fr.clock, fr.out,
                fr.x_out, fr.acc_out, fr.tau, fr.tau_cmd)


@njit
def framed_finish(fr, x):
    """:func:`.cycle_kernel.finish` into the frame's outputs: the solution ``x`` written out."""
    finish(fr.ws, x, fr.x_out, fr.acc_out, fr.tau, fr.tau_cmd)
