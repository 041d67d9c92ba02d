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
The test harness of the ROS layer: start the nodes without ``ros2 launch`` and drive them.

:mod:`.launch_free` starts the bridge, the controller and the recorder as processes in a private
ROS domain; :mod:`.probe` watches them and sends targets and service calls from the calling
process. The test suite, the benchmarks and the main job use them; the product's nodes do not.
"""
