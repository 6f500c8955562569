"""One ament_python package holding three Python packages: landing_gear_sim, antiskid, msg_tools."""

from glob import glob

from setuptools import find_packages, setup

PACKAGE = "landing_gear_sim"
NODES = ("plant", "actuator", "loading_device", "profile", "recorder", "replay")

setup(
    name=PACKAGE,
    version="0.7.0",
    description="Digital twin of an aircraft landing-gear anti-skid test rig",
    license="Apache-2.0",
    python_requires=">=3.10",
    packages=find_packages(include=[PACKAGE, f"{PACKAGE}.*", "antiskid", "antiskid.*",
                                    "msg_tools", "msg_tools.*"]),
    data_files=[
        ("share/ament_index/resource_index/packages", [f"resource/{PACKAGE}"]),
        (f"share/{PACKAGE}", ["package.xml"]),
        (f"share/{PACKAGE}/config", glob("config/*.yaml")),
        (f"share/{PACKAGE}/launch", glob("launch/*.launch.py")),
        # a sourced colcon workspace puts this folder on PATH (colcon.pkg hooks); a plain
        # pip install has the console script in bin/ already, and this folder off PATH
        (f"share/{PACKAGE}/bin", ["scripts/landing-gear-sim"]),
        (f"share/{PACKAGE}/hook", ["hooks/cli_path.dsv", "hooks/cli_path.sh"]),
    ],
    install_requires=[
        "numpy>=1.24",
        "scipy>=1.10",
        "numba>=0.59",
        "matplotlib>=3.7",
        "PyYAML>=6.0",
        "rosbags>=0.11",
        "mcap>=1.1",
        "scikit-learn>=1.3",
        "dask[distributed]>=2024.1",
        "threadpoolctl>=3.1",
    ],
    extras_require={
        # ROS 2 Kilted from PyPI, for machines without a ROS install. Optional so that
        # it never shadows a system ROS inside a workspace.
        "ros": [
            "ros-rclpy",
            "ros-std-msgs",
            "ros-sensor-msgs",
            "ros-geometry-msgs",
            "ros-rosgraph-msgs",
            "ros-rmw-fastrtps-cpp",
            "ros-ament-index-python",
        ],
        # rig log formats beyond CSV, MATLAB v5 and bags (imported only when such a file is read)
        "formats": ["h5py>=3.8", "pyarrow>=14", "asammdf>=7.4", "npTDMS>=1.7", "openpyxl>=3.1"],
        "test": [
            "landing_gear_sim[formats]",
            # below 9.2: there pytest-xdist 3.8's loadgroup loses every group without a word
            # (pytest-xdist issue 1386; test/test_suite_schedule.py)
            "pytest>=7,<9.2",
            "pytest-xdist>=3",
            "ruff>=0.5",
            "import-linter>=2.0",
            "mypy>=1.10",
            "types-PyYAML",
            "colcon-common-extensions",
            "colcon-ros",
            "ros-ament-index-python",
        ],
    },
    entry_points={
        "console_scripts": [
            "landing-gear-sim = landing_gear_sim.cli:main",
            "simulate = landing_gear_sim.cli:simulate_main",
            "bode = landing_gear_sim.cli:bode_main",
            # the nodes: `ros2 run landing_gear_sim <name>` after colcon build
            *(f"{node} = landing_gear_sim.ros.nodes.{node}:main" for node in NODES),
            "antiskid_controller = antiskid.node:main",
        ],
    },
)
