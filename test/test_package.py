# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""The repository is a correct ament_python package: colcon builds it where ``ros2 run`` looks."""

import ast
import os
import re
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from vib_estimator.io.bags import read_wrench_series

ROOT = Path(__file__).resolve().parents[1]
EXECUTABLES = ['vib-estimator', 'estimator_node', 'sim_node', 'bag_replayer', 'bag_recorder']
#: ROS packages the code may import, by the name package.xml must declare
ROS_PACKAGES = {
    'rclpy',
    'std_msgs',
    'geometry_msgs',
    'sensor_msgs',
    'diagnostic_msgs',
    'rosgraph_msgs',
    'std_srvs',
    'rcl_interfaces',
    'builtin_interfaces',
    'launch',
    'launch_ros',
    'ament_index_python',
}


def test_package_xml_declares_every_ros_package_the_code_imports():
    root = ET.parse(ROOT / 'package.xml').getroot()
    assert root.get('format') == '3' and root.findtext('name') == 'vib_estimator'
    assert root.find('export/build_type').text == 'ament_python'
    declared = {e.text for e in root if e.tag in ('exec_depend', 'depend')}
    imported = _imported_by('vib_estimator') | _imported_by('launch')  # both are installed
    missing = (imported & ROS_PACKAGES) - declared
    assert not missing, f'package.xml lacks exec_depend on {sorted(missing)}'


@pytest.mark.skipif(
    not (Path(sys.executable).parent / 'colcon').exists(),
    reason='colcon is installed by make setup',
)
def test_colcon_build_installs_the_executables_where_ros2_run_looks(tmp_path):
    colcon = Path(sys.executable).parent / 'colcon'
    result = subprocess.run(
        # the README's line: colcon build --packages-select vib_estimator
        [
            str(colcon),
            'build',
            '--packages-select',
            'vib_estimator',
            '--base-paths',
            str(ROOT),
            '--build-base',
            str(tmp_path / 'build'),
            '--install-base',
            str(tmp_path / 'install'),
            '--event-handlers',
            'console_direct-',
        ],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert result.returncode == 0, result.stderr + result.stdout
    prefix = tmp_path / 'install' / 'vib_estimator'
    for exe in EXECUTABLES:
        assert os.access(prefix / 'lib' / 'vib_estimator' / exe, os.X_OK), exe
    assert (prefix / 'share/ament_index/resource_index/packages/vib_estimator').is_file()
    share = prefix / 'share' / 'vib_estimator'
    assert (share / 'package.xml').is_file()
    assert list((share / 'config').glob('*.yaml')) and list((share / 'launch').glob('*.py'))
    geometries = sorted(p.name for p in (ROOT / 'config' / 'geometry').glob('*.yaml'))
    assert geometries == sorted(p.name for p in (share / 'config' / 'geometry').glob('*.yaml'))
    shipped = sorted(p.name for p in (ROOT / 'bags').iterdir() if p.is_dir())
    assert shipped and shipped == sorted(p.name for p in (share / 'bags').iterdir() if p.is_dir())
    for name in shipped:  # each bag stays a readable rosbag2 directory
        assert len(read_wrench_series(share / 'bags' / name)) > 1000
    site = next(prefix.glob('lib/python3*/site-packages'))
    run = subprocess.run(
        [str(prefix / 'lib/vib_estimator/vib-estimator'), '--help'],
        env={**os.environ, 'PYTHONPATH': str(site)},
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert run.returncode == 0 and 'analyze' in run.stdout


#: rosdep key of each PyPI requirement that has one (ros/rosdistro rosdep/python.yaml)
ROSDEP_KEYS = {
    'numpy': 'python3-numpy',
    'numba': 'python3-numba',
    'scipy': 'python3-scipy',
    'matplotlib': 'python3-matplotlib',
    'pyyaml': 'python3-yaml',
    'rosbags': 'python3-rosbags-pip',
    'tqdm': 'python3-tqdm',
    'pytest': 'python3-pytest',
    'hypothesis': 'python3-hypothesis',
}
#: import name of requirements whose distribution name differs
IMPORT_NAMES = {'pyyaml': 'yaml'}
#: requirements for building and proving the package here, not for using it
DEVELOPMENT_ONLY = {'wheel', 'colcon-core', 'colcon-ros', 'colcon-package-selection', 'ruff'}


def _requirements():
    names = []
    for line in (ROOT / 'requirements.txt').read_text().splitlines():
        line = line.split('#')[0].strip()
        if line:
            names.append(re.split(r'[\[=<>~! ]', line)[0].lower())
    return names


def _imported_by(folder):
    names = set()
    for path in (ROOT / folder).rglob('*.py'):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Import):
                names |= {a.name.split('.')[0] for a in node.names}
            elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
                names.add(node.module.split('.')[0])
    return names


def test_every_requirement_has_a_rosdep_key_or_a_readme_line():
    root = ET.parse(ROOT / 'package.xml').getroot()
    exec_keys = {e.text for e in root if e.tag in ('exec_depend', 'depend')}
    test_keys = {e.text for e in root if e.tag == 'test_depend'}
    readme = (ROOT / 'README.md').read_text()
    install_table = readme[readme.index('### On a Jazzy machine') :]
    install_table = install_table[: install_table.index('\n#')]
    runtime = _imported_by('vib_estimator')
    problems = []
    for name in _requirements():
        if name.startswith('ros-jazzy-') or name in DEVELOPMENT_ONLY:
            continue  # ROS packages are declared by their own names (test above)
        key = ROSDEP_KEYS.get(name)
        needed_at_run_time = IMPORT_NAMES.get(name, name.replace('-', '_')) in runtime
        if key is None:
            if f'`{name}' not in install_table:
                problems.append(f'{name}: no rosdep key and no line in the README install table')
        elif key not in (exec_keys if needed_at_run_time else exec_keys | test_keys):
            problems.append(f'{name}: package.xml lacks {key}')
    unknown = (exec_keys | test_keys) - set(ROSDEP_KEYS.values()) - ROS_PACKAGES
    assert not problems and not unknown, (problems, f'keys not known to be in rosdep: {unknown}')
