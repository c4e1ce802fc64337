"""The module setup shared by the pytests of bag_runner, lsf_batch and the node on recordings
(test_lsf_batch.py, test_recordings_*.py, test_recordings_node.py): where the executables, the
data and the scratch folder are, the check that the KITTI sample is there (fails under CI=true,
skips otherwise), the bags made from it, and bag_runner / lsf_batch run with a deadline (a hang
fails, nothing is timed).

cmake/ros_tools_tests.cmake runs the tests with LSF_BIN_DIR, LSF_DATA_DIR and LSF_SCRATCH set (one
scratch folder per pytest command, in the build folder); each test module puts its own folder
first on sys.path to import this. Several modules in one pytest command share the scratch folder:
it is emptied once per process, and each bag is made once per process."""

import glob
import hashlib
import os
import shutil
import socket
import subprocess
import sys
import tempfile

import pytest

import batch_bags

SOURCE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
BIN = os.environ.get("LSF_BIN_DIR", "")
DATA = os.environ.get("LSF_DATA_DIR", "")
SCRATCH = os.environ.get("LSF_SCRATCH", os.path.join(tempfile.gettempdir(), "lsf_bag_tests"))
BAG_RUNNER = os.path.join(BIN, "bag_runner")
KITTI_TO_BAG = os.path.join(BIN, "kitti_to_bag")
FUSION_NODE = os.path.join(BIN, "fusion_node")
LSF_BATCH = os.environ.get("LSF_BATCH", os.path.join(SOURCE, "scripts", "lsf_batch"))
LAUNCH_DIR = os.environ.get("LSF_LAUNCH_DIR", os.path.join(SOURCE, "launch"))
DEADLINE = 300  # [s] for any one command, or a launch to give what a test waits for

FB = 721.5377 * 0.5327  # [px m] fx * baseline of the KITTI sample (drive 0009)
TWO_FRAMES = ["0000000000", "0000000005"]  # 0.52 s apart
THREE_FRAMES = TWO_FRAMES + ["0000000010"]
# jpeg (quality 95) against raw, in disparity [px] (doc/tools.md, "Compressed images"), for
# bag_runner (test_recordings_inputs.py) and the node (test_recordings_node.py).
JPEG_SURE_WITHIN_1PX = 0.999   # where the prior's confidence > 0.5: this share within 1 px
JPEG_PRIOR_MEAN = 0.75         # where there is a prior: mean |delta d| below this
JPEG_PRIOR_BEYOND_1PX = 0.10   # where there is a prior: at most this share beyond 1 px
JPEG_VALIDITY = 0.01           # pixels with depth in one and not the other: at most this share

_made = {}  # what this process has made in SCRATCH: {"scratch": True, bag path: its recipe}


def prepare():
    """A test module's setup: fails under CI=true, and skips the module otherwise, when the KITTI
    sample drive is missing; empties SCRATCH on the process's first call."""
    if not os.path.isdir(os.path.join(DATA, batch_bags.DATE, batch_bags.DRIVE)):
        message = "KITTI sample drive missing under LSF_DATA_DIR=%r" % DATA
        if os.environ.get("CI") == "true":
            pytest.fail(message)
        pytest.skip(message, allow_module_level=True)
    if not _made.get("scratch"):
        shutil.rmtree(SCRATCH, ignore_errors=True)
        os.makedirs(SCRATCH)
        _made["scratch"] = True


def kitti_bag(name, frames, extra=()):
    """SCRATCH/<name>.bag: kitti_to_bag of the sample drive's `frames` (with the options `extra`),
    made on the first call in this process."""
    path = os.path.join(SCRATCH, name + ".bag")
    recipe = (tuple(frames), tuple(extra))
    if _made.get(path) != recipe:
        batch_bags.kitti_bag(KITTI_TO_BAG, DATA, SCRATCH, list(frames), path, list(extra))
        _made[path] = recipe
    return path


def drive_bag():
    """SCRATCH/drive.bag: two KITTI frames (0.52 s apart), raw images."""
    return kitti_bag("drive", TWO_FRAMES)


def long_bag():
    """SCRATCH/long.bag: 3 frames restamped at 10 Hz, 3 times: 9 image sets over 0.9 s."""
    return kitti_bag("long", THREE_FRAMES, ["--period", "0.1", "--cycles", "3"])


# The bags as module-scope pytest fixtures `drive` and `long_bag`; a test module imports them
# (from bag_tool_setup import drive_fixture, long_bag_fixture) instead of declaring its own.
@pytest.fixture(scope="module", name="drive")
def drive_fixture():
    """Two KITTI frames (0.52 s apart), raw images."""
    return drive_bag()


@pytest.fixture(scope="module", name="long_bag")
def long_bag_fixture():
    """3 frames restamped at 10 Hz, 3 times: 9 image sets over 0.9 s."""
    return long_bag()


def run(command, **kwargs):
    """`command` (any items, made strings) with its output captured, one OpenMP thread, and the
    deadline unless `timeout` is given."""
    kwargs.setdefault("timeout", DEADLINE)
    return subprocess.run([str(c) for c in command], stdout=subprocess.PIPE,
                          stderr=subprocess.PIPE, universal_newlines=True,
                          env=dict(os.environ, OMP_NUM_THREADS="1"), **kwargs)


def bag_runner(*args):
    return run([BAG_RUNNER] + list(args))


def batch(*args, **kwargs):
    """lsf_batch on its embedded LocalCluster of 2 worker processes of one thread each."""
    return run([sys.executable, LSF_BATCH, "--bag-runner", BAG_RUNNER, "--workers", 2,
                "--threads-per-worker", 1] + list(args), **kwargs)


def scratch(name):
    """SCRATCH/<name>, removed if it exists."""
    path = os.path.join(SCRATCH, name)
    shutil.rmtree(path, ignore_errors=True)
    return path


def digest(path):
    with open(path, "rb") as f:
        return hashlib.sha256(f.read()).hexdigest()


def pngs(folder, recursive=False):
    """{file name: bytes} of the PNGs directly in `folder`; with `recursive`, of those in its
    sub-folders too, named by their path relative to `folder`."""
    pattern = os.path.join(folder, "**", "*.png") if recursive else os.path.join(folder, "*.png")
    found = {}
    for path in glob.glob(pattern, recursive=recursive):
        with open(path, "rb") as f:
            found[os.path.relpath(path, folder)] = f.read()
    return found


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]
