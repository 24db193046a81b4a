# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""ament_python package definition for vib_estimator."""

import os
from glob import glob

from setuptools import find_packages, setup

PACKAGE = 'vib_estimator'
#: the recorded experiments keep their folder structure (a rosbag2 bag is a directory)
BAG_DIRS = sorted({os.path.dirname(f) for f in glob('bags/**/*.*', recursive=True)})

setup(
    name=PACKAGE,
    version='0.1.0',
    packages=find_packages(exclude=['test']),
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + PACKAGE]),
        ('share/' + PACKAGE, ['package.xml']),
        ('share/' + PACKAGE + '/config', glob('config/*.yaml') + glob('config/*.rviz')),
        ('share/' + PACKAGE + '/config/geometry', glob('config/geometry/*.yaml')),
        ('share/' + PACKAGE + '/launch', glob('launch/*.py')),
    ]
    + [('share/' + PACKAGE + '/' + d, glob(d + '/*.*')) for d in BAG_DIRS],
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer='vib_estimator developers',
    maintainer_email='vib-estimator@example.com',
    description='Fast on-line algebraic frequency estimator of lightly damped vibrations '
    '(Trapero, Sira-Ramirez, Feliu), with flexible-arm simulator and bag tools.',
    license='Apache-2.0',
    tests_require=['pytest'],
    entry_points={
        'console_scripts': [
            'vib-estimator = vib_estimator.cli:main',
            'estimator_node = vib_estimator.nodes.estimator_node:main',
            'sim_node = vib_estimator.nodes.sim_node:main',
            'shaper_node = vib_estimator.nodes.shaper_node:main',
            'bag_replayer = vib_estimator.nodes.bag_replayer:main',
            'bag_recorder = vib_estimator.nodes.bag_recorder:main',
        ],
    },
)
