"""The MakeHuman base mesh and its reference skeleton, loaded once for the auto-rig tests (none changes it)."""
import pytest

from kinect_retarget.sim.autorig_scoring import load_makehuman


@pytest.fixture(scope="session")
def mh(data_dir):
    return load_makehuman(data_dir / "meshes" / "makehuman")
