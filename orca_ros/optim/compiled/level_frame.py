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
A level's kernel arguments in one numba structure: a call passes it and the cycle's budget.

Each level below the first is prepared and solved by one kernel call per cycle
(:func:`.lower_level.prepare_and_solve`, or its GENERALIZED form). Its eight or nine arguments
(three or four structures, an array, scalars) are each unboxed at every call in the control loop;
the frame holds what stays from cycle to cycle (the level's state, its back-ends' DAQP states,
their time models, the clock, the iteration floor), made with the level.
"""

from __future__ import annotations

from numba.experimental import structref

from .lower_level import prepare_and_solve, prepare_and_solve_generalized
from ...utils.jit import njit
from ...utils.struct_type import StructType

#: the fields, in order: a strict level's reference and banded back-ends are its strict one
FIELDS = ('s', 'strict', 'ref', 'banded', 'timing', 'ref_timing', 'clock', 'least')


@structref.register
class LevelFrameType(StructType):
    """Its fields' types: see struct_type."""


class LevelFrame(structref.StructRefProxy):
    """What a level's kernels read besides the cycle's budget (fields: :data:`FIELDS`)."""


structref.define_proxy(LevelFrame, LevelFrameType, list(FIELDS))


@njit
def _construct(*fields):
    """Make the frame in compiled code: cached on disk, unlike the proxy's own constructor."""
    return LevelFrame(*fields)


def make_level_frame(state, strict, reference=None, banded=None) -> LevelFrame:
    """Return the frame of a level's state and its back-ends (DirectDAQPBackend)."""
    ref, band = reference or strict, banded or strict
    return _construct(state, strict.solve_state, ref.solve_state, band.solve_state, strict.timing,
                      ref.timing, strict.clock, strict.min_iterations)


@njit
def framed_strict(fr, mask, deadline, most):
    """:func:`.lower_level.prepare_and_solve` with the frame's arguments."""
    return prepare_and_solve(fr.s, fr.strict, mask, deadline, most, fr.least, fr.timing,
                             fr.clock)


@njit
def framed_generalized(fr, deadline, most):
    """:func:`.lower_level.prepare_and_solve_generalized` with the frame's arguments."""
    return prepare_and_solve_generalized(fr.s, fr.ref, fr.banded, fr.strict, deadline, most,
                                         fr.least, fr.ref_timing, fr.clock)
