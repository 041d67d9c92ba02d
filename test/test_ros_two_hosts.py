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
The bridge and the controller on two "hosts": two network namespaces joined by a veth pair.

Each namespace has its own network stack, so DDS finds the other side only through the veth link,
as across two machines (UDP only: Fast DDS's shared-memory transport would otherwise take the
shortcut through /dev/shm, which the namespaces share). The main job, attached from the bridge's
side, sends its targets to the controller on the other side and must reach them.
"""

import json
import os
import shutil
import subprocess
import sys

from orca_ros.ros.testing.launch_free import free_domain_id, Procs
import pytest

UDP_ONLY = """<?xml version="1.0" encoding="UTF-8" ?>
<profiles xmlns="http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles">
  <transport_descriptors>
    <transport_descriptor>
      <transport_id>udp_only</transport_id>
      <type>UDPv4</type>
    </transport_descriptor>
  </transport_descriptors>
  <participant profile_name="udp_only" is_default_profile="true">
    <rtps>
      <userTransports><transport_id>udp_only</transport_id></userTransports>
      <useBuiltinTransports>false</useBuiltinTransports>
    </rtps>
  </participant>
</profiles>
"""


def _ip(*args):
    return subprocess.run(['ip', *args], check=True, capture_output=True, text=True).stdout


@pytest.fixture
def two_hosts():
    if shutil.which('ip') is None or os.geteuid() != 0:
        pytest.skip('two network namespaces need root and iproute2 (ip netns)')
    tag = os.getpid() % 100000
    hosts = (f'orca_a{tag}', f'orca_b{tag}')
    links = (f'oa{tag}', f'ob{tag}')
    subnet = f'10.{77 + tag % 100}.{tag % 250}'
    try:
        _ip('netns', 'add', hosts[0])
    except subprocess.CalledProcessError as exc:
        pytest.skip(f'network namespaces not permitted here: {exc.stderr.strip()}')
    try:
        try:
            _ip('netns', 'add', hosts[1])
            _ip('link', 'add', links[0], 'type', 'veth', 'peer', 'name', links[1])
            for k, (ns, link) in enumerate(zip(hosts, links)):
                _ip('link', 'set', link, 'netns', ns)
                _ip('-n', ns, 'addr', 'add', f'{subnet}.{k + 1}/24', 'dev', link)
                _ip('-n', ns, 'link', 'set', link, 'up')
                _ip('-n', ns, 'link', 'set', 'lo', 'up')
                # DDS discovery is multicast
                _ip('-n', ns, 'route', 'add', '224.0.0.0/4', 'dev', link)
        except subprocess.CalledProcessError as exc:
            pytest.skip(f'a veth pair between namespaces is not permitted: {exc.stderr.strip()}')
        yield hosts, links
    finally:
        for ns in hosts:  # deleting a namespace deletes its end of the veth pair
            subprocess.run(['ip', 'netns', 'del', ns], capture_output=True)


def _bytes(ns, link):
    stats = json.loads(_ip('-n', ns, '-s', '-j', 'link', 'show', link))[0]['stats64']
    return stats['rx']['bytes'], stats['tx']['bytes']


def test_bridge_and_controller_on_two_hosts_reach_targets_over_dds(two_hosts, tmp_path):
    (host_a, host_b), (link_a, link_b) = two_hosts
    profile = tmp_path / 'udp_only.xml'
    profile.write_text(UDP_ONLY)
    env = {
        'ROS_AUTOMATIC_DISCOVERY_RANGE': 'SUBNET',
        'FASTRTPS_DEFAULT_PROFILES_FILE': str(profile),
    }
    domain = free_domain_id()
    procs = Procs(domain, str(tmp_path), local_only=False)
    procs.start_arm_bridge('lockstep', prefix=('ip', 'netns', 'exec', host_a), env=env)
    procs.start_arm_controller('lockstep', prefix=('ip', 'netns', 'exec', host_b), env=env)
    try:
        rx0, tx0 = _bytes(host_b, link_b)
        # the main job attached on the bridge's host: targets and the recording cross the link
        job = subprocess.run(
            ['ip', 'netns', 'exec', host_a, sys.executable, '-m', 'orca_ros.ros.main_job',
             '--attach', '--output-dir', str(tmp_path / 'job')],
            capture_output=True, text=True, timeout=900,
            env={**os.environ, **env, 'ROS_DOMAIN_ID': str(domain), 'MPLBACKEND': 'Agg'},
        )
        assert job.returncode == 0, (
            job.stdout[-3000:] + job.stderr[-2000:] + procs.log('controller')[-2000:]
        )
        assert 'RESULT: every target reached' in job.stdout
        rx, tx = _bytes(host_b, link_b)
        # the controller's host received the joint states and sent the commands over the veth:
        # thousands of each
        assert rx - rx0 > 1_000_000 and tx - tx0 > 500_000, (rx - rx0, tx - tx0)
        assert 'Traceback' not in procs.log('controller') + procs.log('bridge')
    finally:
        procs.stop()
