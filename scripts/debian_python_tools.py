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
Install pure-Python linters that PyPI lacks from Debian's archive into the current environment.

``ament_copyright`` (one of the three linter tests ``ros2 pkg create`` generates) is not published
on PyPI; Debian packages it (bookworm: 0.13.2). Each .deb is pinned by its SHA-256, downloaded
from deb.debian.org, and only its ``usr/lib/python3/dist-packages`` tree (modules + egg-info with
the entry points) is copied into this interpreter's site-packages. No root, no apt.
"""

import hashlib
import io
import os
import sys
import sysconfig
import tarfile
import urllib.request

POOL = 'http://deb.debian.org/debian/pool/main/r/ros2-ament-lint/'
DEBS = {
    'python3-ament-lint_0.13.2-4_all.deb':
        'ed097c6455f44aa4accdd8dd68eec854fc7e575b8d01c79ded98b3f64f56897a',
    'python3-ament-copyright_0.13.2-4_all.deb':
        '1218209bb606535330f1e5e0ec9a8b32bceb0a45cef08de0680ea9327db6aa2f',
}
PREFIX = './usr/lib/python3/dist-packages/'


def ar_members(blob: bytes):
    """Yield (name, data) of the members of an ar archive (the container of a .deb)."""
    if not blob.startswith(b'!<arch>\n'):
        raise ValueError('not an ar archive')
    pos = 8
    while pos + 60 <= len(blob):
        header = blob[pos:pos + 60]
        name = header[:16].decode().strip().rstrip('/')
        size = int(header[48:58].decode().strip())
        yield name, blob[pos + 60:pos + 60 + size]
        pos += 60 + size + (size % 2)


def install(deb: str, sha256: str, target: str) -> None:
    with urllib.request.urlopen(POOL + deb, timeout=120) as r:
        blob = r.read()
    digest = hashlib.sha256(blob).hexdigest()
    if digest != sha256:
        raise SystemExit(f'{deb}: SHA-256 {digest} is not the pinned {sha256}')
    data = dict(ar_members(blob))['data.tar.xz']
    with tarfile.open(fileobj=io.BytesIO(data), mode='r:xz') as tar:
        for member in tar.getmembers():
            if not member.name.startswith(PREFIX) or not (member.isfile() or member.isdir()):
                continue
            rel = member.name[len(PREFIX):]
            if not rel or '..' in rel.split('/'):
                continue
            dest = os.path.join(target, rel)
            if member.isdir():
                os.makedirs(dest, exist_ok=True)
                continue
            os.makedirs(os.path.dirname(dest), exist_ok=True)
            with tar.extractfile(member) as src, open(dest, 'wb') as out:
                out.write(src.read())


def main() -> int:
    try:
        import ament_copyright  # noqa: F401
        return 0
    except ImportError:
        pass
    target = sysconfig.get_paths()['purelib']
    try:
        for deb, sha in DEBS.items():
            install(deb, sha, target)
    except OSError as exc:  # no route to deb.debian.org: the rest of the set-up goes on
        print(f'ament_copyright not installed ({POOL} unreachable: {exc})', file=sys.stderr)
        return 1
    print(f'installed ament_copyright 0.13.2 (Debian) into {target}', file=sys.stderr)
    return 0


if __name__ == '__main__':
    sys.exit(main())
