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
"""How the tasks of a controller are combined."""

from __future__ import annotations

from enum import Enum


class ResolutionStrategy(Enum):
    ONE_LEVEL_WEIGHTED = 'one_level_weighted'  # all tasks in one weighted QP (levels ignored)
    MULTI_LEVEL_WEIGHTED = 'multi_level_weighted'  # strict levels, weighted inside each level
    GENERALIZED = 'generalized'  # continuous priorities between tasks

    @classmethod
    def from_string(cls, name: str) -> 'ResolutionStrategy':
        key = str(name).strip().lower().replace('-', '_')
        aliases = {
            'onelevelweighted': 'one_level_weighted',
            'multilevelweighted': 'multi_level_weighted',
        }
        key = aliases.get(key.replace('_', ''), key)
        for s in cls:
            if s.value == key:
                return s
        raise ValueError(
            f"unknown resolution strategy '{name}' (expected one of: "
            f"{', '.join(s.value for s in cls)})"
        )
