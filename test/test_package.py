"""The repository is a correct ament_python package: colcon builds it where ``ros2 run`` looks."""
import ast
import os
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from vib_estimator.io.bags import read_wrench_series

ROOT = Path(__file__).resolve().parents[1]
EXECUTABLES = ['vib-estimator', 'estimator_node', 'sim_node', 'bag_replayer', 'bag_recorder']
#: ROS packages the code may import, by the name package.xml must declare
ROS_PACKAGES = {'rclpy', 'std_msgs', 'geometry_msgs', 'sensor_msgs', 'diagnostic_msgs', 'rosgraph_msgs',
                'std_srvs', 'rcl_interfaces', 'builtin_interfaces'}


def test_package_xml_declares_every_ros_package_the_code_imports():
    root = ET.parse(ROOT / 'package.xml').getroot()
    assert root.get('format') == '3' and root.findtext('name') == 'vib_estimator'
    assert root.find('export/build_type').text == 'ament_python'
    declared = {e.text for e in root if e.tag in ('exec_depend', 'depend')}
    imported = set()
    for path in (ROOT / 'vib_estimator').rglob('*.py'):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Import):
                imported |= {a.name.split('.')[0] for a in node.names}
            elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
                imported.add(node.module.split('.')[0])
    missing = (imported & ROS_PACKAGES) - declared
    assert not missing, f'package.xml lacks exec_depend on {sorted(missing)}'


@pytest.mark.skipif(not (Path(sys.executable).parent / 'colcon').exists(),
                    reason='colcon is installed by make setup')
def test_colcon_build_installs_the_executables_where_ros2_run_looks(tmp_path):
    colcon = Path(sys.executable).parent / 'colcon'
    result = subprocess.run(
        [str(colcon), 'build', '--base-paths', str(ROOT), '--build-base', str(tmp_path / 'build'),
         '--install-base', str(tmp_path / 'install'), '--event-handlers', 'console_direct-'],
        cwd=tmp_path, capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stderr + result.stdout
    prefix = tmp_path / 'install' / 'vib_estimator'
    for exe in EXECUTABLES:
        assert os.access(prefix / 'lib' / 'vib_estimator' / exe, os.X_OK), exe
    assert (prefix / 'share/ament_index/resource_index/packages/vib_estimator').is_file()
    share = prefix / 'share' / 'vib_estimator'
    assert (share / 'package.xml').is_file()
    assert list((share / 'config').glob('*.yaml')) and list((share / 'launch').glob('*.py'))
    shipped = sorted(p.name for p in (ROOT / 'bags').iterdir() if p.is_dir())
    assert shipped and shipped == sorted(p.name for p in (share / 'bags').iterdir() if p.is_dir())
    for name in shipped:                      # each bag stays a readable rosbag2 directory
        assert len(read_wrench_series(share / 'bags' / name)) > 1000
    site = next(prefix.glob('lib/python3*/site-packages'))
    run = subprocess.run([str(prefix / 'lib/vib_estimator/vib-estimator'), '--help'],
                         env={**os.environ, 'PYTHONPATH': str(site)}, capture_output=True,
                         text=True, timeout=60)
    assert run.returncode == 0 and 'analyze' in run.stdout
