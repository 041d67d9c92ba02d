import os

import numpy as np
import pytest

import orca_ros as orca


@pytest.fixture(scope="session")
def lwr_urdf():
    return orca.default_urdf_path()


@pytest.fixture(scope="session")
def iiwa_urdf():
    import pybullet_data

    return os.path.join(pybullet_data.getDataPath(), "kuka_iiwa", "model.urdf")


@pytest.fixture
def rng():
    return np.random.default_rng(1234)
