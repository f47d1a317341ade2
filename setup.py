from glob import glob

from setuptools import find_packages, setup

package_name = 'twodisk_ros'

setup(
    name=package_name,
    version='0.1.0',
    packages=find_packages(exclude=['tests', 'benchmarks']),
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml']),
        ('share/' + package_name + '/config',
         glob('config/*.yaml') + glob('config/*.rviz') + glob('config/*.json')),
    ],
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer='twodisk_ros maintainers',
    maintainer_email='maintainers@twodisk-ros.invalid',
    description='Rolling two-disk bodies (Oloid, Two-Circle-Roller) for ROS 2 Jazzy.',
    license='Apache-2.0',
    tests_require=['pytest'],
    entry_points={
        'console_scripts': [
            'roller = twodisk_ros.roller:main',
            'twodisk-inspect = twodisk_ros.inspector.cli:main',
            'twodisk-figures = twodisk_ros.plotting.figures:main',
            'twodisk-animate = twodisk_ros.plotting.animate_cli:main',
            'twodisk-sweep = twodisk_ros.sweep.cli:main',
            'twodisk-view = twodisk_ros.view.cli:main',
            'twodisk-explore = twodisk_ros.explore.cli:main',
        ],
    },
)
