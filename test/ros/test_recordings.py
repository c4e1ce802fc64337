"""Issue 33: recordings as users keep them, through bag_runner, lsf_batch and fusion.launch's
filters (pytest, run by `catkin_make run_tests`). One test per row of the issue's table:
  1  an output that is an input (--out-bag, --frames-csv, --out; the same file, a hard or symbolic
     link) is refused naming both, the bag untouched;
  2  a folder made from another drive, method or parameters is refused saying what differs
     (bag_runner --resume and lsf_batch), --force starts it over;
  3  images recorded as sensor_msgs/CompressedImage: png gives the raw bag's depth PNGs byte for
     byte (bag_runner and lsf_batch), jpeg within the tolerance of doc/tools.md;
  5  a swapped stereo pair is warned about once, naming the fix;
  6  a killed run leaves no temporary file ending in .png, and --resume removes its leftovers;
  7, 8  fusion.launch's box corners in any order; one corner alone, or not three numbers, refused
     by roslaunch naming it;
  9  a remap with a typo is refused naming the nearest name; relative topics resolved as ROS does;
  10 a bag that is no bag says what it is (random bytes, empty, a folder, missing);
  11 an empty time window is refused before any work;
  12 a lost scheduler stops lsf_batch and its tasks' bag_runners with one line; an unreachable
     one is one line too;
  13 --chunk has a floor and the tasks a limit;
  14 an output folder that cannot be written is refused before any work, with the reason;
  15 bag_runner --cloud writes x y z rgb, as kitti_runner --save-pcd.
The bags are written at test time from the KITTI sample into LSF_SCRATCH (the build folder, not
committed). Missing data fails under CI=true and skips otherwise. No timing is asserted."""

import glob
import hashlib
import os
import re
import shutil
import signal
import socket
import subprocess
import sys
import time

import pytest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import batch_bags  # noqa: E402
import recording_bags  # noqa: E402

SOURCE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
BIN = os.environ.get("LSF_BIN_DIR", "")
DATA = os.environ.get("LSF_DATA_DIR", "")
SCRATCH = os.environ.get("LSF_SCRATCH", "/tmp/lsf_recordings_test")
BAG_RUNNER = os.path.join(BIN, "bag_runner")
KITTI_TO_BAG = os.path.join(BIN, "kitti_to_bag")
LSF_BATCH = os.environ.get("LSF_BATCH", os.path.join(SOURCE, "scripts", "lsf_batch"))
LAUNCH_DIR = os.environ.get("LSF_LAUNCH_DIR", os.path.join(SOURCE, "launch"))
DEADLINE = 300  # [s] for any one command: a hang fails, nothing is timed
SWAP_REMAPS = ["left/image_rect_color:=/stereo/right/image_rect_color",
               "right/image_rect_color:=/stereo/left/image_rect_color",
               "left/camera_info:=/stereo/right/camera_info",
               "right/camera_info:=/stereo/left/camera_info"]
# jpeg (quality 95) against raw, in disparity [px] (doc/tools.md, "Compressed images").
JPEG_SURE_WITHIN_1PX = 0.999   # where the prior's confidence > 0.5: this share within 1 px
JPEG_PRIOR_MEAN = 0.75         # where there is a prior: mean |delta d| below this
JPEG_PRIOR_BEYOND_1PX = 0.10   # where there is a prior: at most this share beyond 1 px
JPEG_VALIDITY = 0.01           # pixels with depth in one and not the other: at most this share


def setup_module():
    if not os.path.isdir(os.path.join(DATA, batch_bags.DATE, batch_bags.DRIVE)):
        message = "KITTI sample drive missing under LSF_DATA_DIR=%r" % DATA
        if os.environ.get("CI") == "true":
            pytest.fail(message)
        pytest.skip(message, allow_module_level=True)
    shutil.rmtree(SCRATCH, ignore_errors=True)
    os.makedirs(SCRATCH)


def run(command, **kwargs):
    kwargs.setdefault("timeout", DEADLINE)
    return subprocess.run([str(c) for c in command], stdout=subprocess.PIPE,
                          stderr=subprocess.PIPE, universal_newlines=True,
                          env=dict(os.environ, OMP_NUM_THREADS="1"), **kwargs)


def bag_runner(*args):
    return run([BAG_RUNNER] + list(args))


def batch(*args, **kwargs):
    return run([sys.executable, LSF_BATCH, "--bag-runner", BAG_RUNNER, "--workers", 2,
                "--threads-per-worker", 1] + list(args), **kwargs)


def scratch(name):
    path = os.path.join(SCRATCH, name)
    shutil.rmtree(path, ignore_errors=True)
    return path


def digest(path):
    with open(path, "rb") as f:
        return hashlib.sha256(f.read()).hexdigest()


def pngs(folder):
    """{file name: bytes} of the PNGs directly in `folder`."""
    found = {}
    for path in glob.glob(os.path.join(folder, "*.png")):
        with open(path, "rb") as f:
            found[os.path.basename(path)] = f.read()
    return found


def stamp_png(name):
    stem = name[:-4] if name.endswith(".png") else ""
    sec, _, nsec = stem.partition(".")
    return sec.isdigit() and nsec.isdigit() and len(nsec) == 9


@pytest.fixture(scope="module")
def drive():
    """Two KITTI frames (0.52 s apart), raw images."""
    return batch_bags.kitti_bag(KITTI_TO_BAG, DATA, SCRATCH, ["0000000000", "0000000005"],
                                os.path.join(SCRATCH, "drive.bag"))


@pytest.fixture(scope="module")
def long_bag():
    """3 frames restamped at 10 Hz, 3 times: 9 image sets over 0.9 s."""
    return batch_bags.kitti_bag(KITTI_TO_BAG, DATA, SCRATCH,
                                ["0000000000", "0000000005", "0000000010"],
                                os.path.join(SCRATCH, "long.bag"),
                                ["--period", "0.1", "--cycles", "3"])


@pytest.fixture(scope="module")
def raw_depth(drive):
    """bag_runner on the raw bag (with the confidence of the prior)."""
    out = scratch("raw_depth")
    result = bag_runner("--bag", drive, "--out", out, "--confidence")
    assert result.returncode == 0, result.stderr
    return out


# Row 1 ------------------------------------------------------------------------------------------
def test_row01_an_output_that_is_an_input_is_refused_and_the_bag_untouched(drive):
    before = digest(drive)
    folder = os.path.dirname(drive)
    link, hard = os.path.join(folder, "link.bag"), os.path.join(folder, "hard.bag")
    for path in (link, hard):
        if os.path.lexists(path):
            os.remove(path)
    os.symlink(drive, link)
    os.link(drive, hard)
    out = scratch("row01")
    for option, path in (("--out-bag", drive), ("--frames-csv", drive), ("--out-bag", link),
                         ("--frames-csv", hard), ("--out-bag", hard)):
        result = bag_runner("--bag", drive, "--out", out, option, path)
        assert result.returncode == 1, (option, path, result.stderr)
        assert "refusing to write %s %s: it is the input bag %s" % (option, path, drive) \
            in result.stderr, result.stderr
        assert digest(drive) == before, (option, path)
    result = bag_runner("--bag", drive, "--out", drive)
    assert result.returncode == 1
    assert "refusing to write --out folder %s: it is the input bag" % drive in result.stderr
    assert digest(drive) == before
    assert not os.path.exists(out)  # refused before anything was written


# Row 2 ------------------------------------------------------------------------------------------
def test_row02_bag_runner_resume_over_another_method_is_refused_and_force_starts_over(drive):
    out = scratch("row02_resume")
    assert bag_runner("--bag", drive, "--out", out, "--method", "lidar_bf").returncode == 0
    made = pngs(out)
    assert len(made) == 2
    result = bag_runner("--bag", drive, "--out", out, "--resume", "--method", "lidar_bi")
    assert result.returncode == 1, result.stderr
    assert "param.method: lidar_bf -> lidar_bi" in result.stderr
    assert "--force" in result.stderr
    assert pngs(out) == made
    result = bag_runner("--bag", drive, "--out", out, "--resume", "--method", "lidar_bi",
                        "--force")
    assert result.returncode == 0, result.stderr
    fresh = scratch("row02_fresh")
    assert bag_runner("--bag", drive, "--out", fresh, "--method", "lidar_bi").returncode == 0
    assert pngs(out) == pngs(fresh) != made


def test_row02_lsf_batch_refuses_another_drive_of_the_same_name_and_other_options(drive,
                                                                                  long_bag):
    a, b = os.path.join(SCRATCH, "a"), os.path.join(SCRATCH, "b")
    for folder, source in ((a, drive), (b, long_bag)):
        os.makedirs(folder, exist_ok=True)
        shutil.copy(source, os.path.join(folder, "x.bag"))
    out = scratch("row02_batch")
    result = batch("--out", out, "--method", "lidar_bi", os.path.join(a, "x.bag"))
    assert result.returncode == 0, result.stderr
    first = pngs(os.path.join(out, "x"))
    assert len(first) == 2
    # Another drive with the same file name.
    result = batch("--out", out, "--method", "lidar_bi", os.path.join(b, "x.bag"))
    assert result.returncode == 1, result.stderr
    assert os.path.join(b, "x.bag") + ": " in result.stderr
    assert "bag1.size:" in result.stderr and "--force" in result.stderr
    assert pngs(os.path.join(out, "x")) == first
    # The same drive with another method.
    result = batch("--out", out, "--method", "lidar_bf", os.path.join(a, "x.bag"))
    assert result.returncode == 1, result.stderr
    assert "param.method: lidar_bi -> lidar_bf" in result.stderr
    # --force: the other drive's files, as bag_runner on it alone.
    result = batch("--out", out, "--method", "lidar_bi", "--force", os.path.join(b, "x.bag"))
    assert result.returncode == 0, result.stderr
    alone = scratch("row02_alone")
    assert bag_runner("--bag", long_bag, "--out", alone, "--method", "lidar_bi").returncode == 0
    assert pngs(os.path.join(out, "x")) == pngs(alone)
    assert len(pngs(alone)) == 9


# Row 3 ------------------------------------------------------------------------------------------
def test_row03_compressed_png_gives_the_raw_depth_in_bag_runner_and_lsf_batch(drive, raw_depth):
    png = recording_bags.compressed_copy(drive, os.path.join(SCRATCH, "png.bag"), "png")
    out = scratch("row03_png")
    result = bag_runner("--bag", png, "--out", out)
    assert result.returncode == 0, result.stderr
    assert "/stereo/left/image_rect_color/compressed: read there" in result.stderr
    assert pngs(out) == pngs(raw_depth)
    assert len(pngs(out)) == 2
    # Remapped to the compressed topics by name, as a user of another rig would.
    out = scratch("row03_remapped")
    result = bag_runner("--bag", png, "--out", out,
                        "left/image_rect_color:=/stereo/left/image_rect_color/compressed",
                        "right/image_rect_color:=/stereo/right/image_rect_color/compressed")
    assert result.returncode == 0, result.stderr
    assert pngs(out) == pngs(raw_depth)
    out = scratch("row03_batch")
    result = batch("--out", out, png)
    assert result.returncode == 0, result.stderr
    assert pngs(os.path.join(out, "png")) == pngs(raw_depth)


def disparity_agreement(raw_folder, other_folder, fB):
    """Per frame: (sure within 1 px share, prior mean |dd|, prior beyond 1 px share, validity
    share), the regions from the raw run's confidence."""
    import cv2
    import numpy as np
    out = []
    for name in sorted(pngs(raw_folder)):
        a = cv2.imread(os.path.join(raw_folder, name), cv2.IMREAD_UNCHANGED) / 256.0
        b = cv2.imread(os.path.join(other_folder, name), cv2.IMREAD_UNCHANGED) / 256.0
        c = cv2.imread(os.path.join(raw_folder, "confidence", name), cv2.IMREAD_UNCHANGED) / 65535.0
        both = (a > 0) & (b > 0)
        error = np.abs(fB / np.where(both, a, 1.0) - fB / np.where(both, b, 1.0))
        sure, prior = both & (c > 0.5), both & (c > 0)
        out.append(((error[sure] <= 1.0).mean(), error[prior].mean(), (error[prior] > 1.0).mean(),
                    ((a > 0) != (b > 0)).mean()))
    return out


def test_row03_compressed_jpeg_is_within_the_stated_tolerance(drive, raw_depth):
    jpeg = recording_bags.compressed_copy(drive, os.path.join(SCRATCH, "jpeg.bag"), "jpeg", 95)
    out = scratch("row03_jpeg")
    result = bag_runner("--bag", jpeg, "--out", out)
    assert result.returncode == 0, result.stderr
    assert sorted(pngs(out)) == sorted(pngs(raw_depth))
    for sure, prior_mean, prior_beyond, validity in disparity_agreement(
            raw_depth, out, 721.5377 * 0.5327):
        assert sure >= JPEG_SURE_WITHIN_1PX
        assert prior_mean < JPEG_PRIOR_MEAN
        assert prior_beyond <= JPEG_PRIOR_BEYOND_1PX
        assert validity <= JPEG_VALIDITY


def test_row03_an_image_topic_of_another_type_is_named_before_any_work(drive):
    result = bag_runner("--bag", drive, "--out", scratch("row03_type"),
                        "left/image_rect_color:=/velodyne_points")
    assert result.returncode == 1
    assert ("/velodyne_points holds sensor_msgs/PointCloud2, but left/image_rect_color needs "
            "sensor_msgs/CompressedImage or sensor_msgs/Image") in result.stderr, result.stderr


# Row 5 ------------------------------------------------------------------------------------------
def test_row05_a_swapped_pair_is_warned_once_naming_the_fix(drive, long_bag):
    result = bag_runner("--bag", long_bag, "--out", scratch("row05_swapped"), "--method",
                        "lidar_bi", *SWAP_REMAPS)
    assert result.returncode == 0, result.stderr
    assert result.stderr.count("looks swapped") == 1, result.stderr
    assert ("left/image_rect_color:=/stereo/left/image_rect_color "
            "right/image_rect_color:=/stereo/right/image_rect_color") in result.stderr
    assert "left camera_info P[3] = -384.381" in result.stderr
    result = bag_runner("--bag", drive, "--out", scratch("row05_in_order"), "--method", "lidar_bi")
    assert result.returncode == 0, result.stderr
    assert "swapped" not in result.stderr


# Row 6 ------------------------------------------------------------------------------------------
def test_row06_a_killed_run_leaves_no_png_temporary_and_resume_removes_leftovers(long_bag):
    out = scratch("row06")
    caught = 0
    for attempt in range(5):  # kill it while it writes a file, if the poll sees one
        proc = subprocess.Popen([BAG_RUNNER, "--bag", long_bag, "--out", out, "--method",
                                 "lidar_bi", "--resume"], stdout=subprocess.DEVNULL,
                                stderr=subprocess.DEVNULL, env=dict(os.environ, OMP_NUM_THREADS="1"))
        deadline = time.time() + DEADLINE
        while proc.poll() is None and time.time() < deadline:
            names = os.listdir(out) if os.path.isdir(out) else []
            if any(n.endswith(".tmp") or ".tmp" in n for n in names):
                proc.send_signal(signal.SIGKILL)
                caught += 1
                break
        proc.wait()
        for name in os.listdir(out):
            if name.endswith(".png"):
                assert stamp_png(name), "a temporary PNG after a SIGKILL: %s" % name
        if len(pngs(out)) == 9:
            break
    # An interrupted run of an older bag_runner left its temporary PNG; this one's too.
    stamp = sorted(pngs(out))[0] if pngs(out) else "1317042504.967930794.png"
    dead = recording_bags.dead_pid()
    old = os.path.join(out, "%s.tmp%d.png" % (stamp, dead))
    new = os.path.join(out, ".%s~%d@%s.tmp" % (stamp, dead, socket.gethostname()))
    for path in (old, new):
        with open(path, "wb") as f:
            f.write(b"\x89PNG half")
    result = bag_runner("--bag", long_bag, "--out", out, "--method", "lidar_bi", "--resume")
    assert result.returncode == 0, result.stderr
    removed = re.search(r"removed (\d+) temporary files of an interrupted run", result.stderr)
    assert removed and int(removed.group(1)) >= 2, result.stderr
    assert not os.path.exists(old) and not os.path.exists(new)
    assert len(glob.glob(os.path.join(out, "*.png"))) == 9
    assert all(stamp_png(n) for n in pngs(out))
    print("runs killed while a temporary file existed: %d" % caught)


# Rows 7 and 8 -----------------------------------------------------------------------------------
def roslaunch(option, *args):
    """roslaunch --dump-params (exit 0 even when the file cannot be loaded) or --nodes (exit 1
    then) on fusion.launch: the launch file is read, nothing is started."""
    return run(["/usr/bin/python3", "/usr/bin/roslaunch", option,
                os.path.join(LAUNCH_DIR, "fusion.launch")] + list(args))


def test_row07_box_corners_in_any_order_make_the_same_box():
    ordered = roslaunch("--dump-params", "self_filter_min:=-8 -8 -3", "self_filter_max:=8 8 3")
    swapped = roslaunch("--dump-params", "self_filter_min:=8 8 3", "self_filter_max:=-8 -8 -3")
    mixed = roslaunch("--dump-params", "self_filter_min:=8 -8 3", "self_filter_max:=-8 8 -3")
    for result in (ordered, swapped, mixed):
        assert result.returncode == 0, result.stderr
        box = {line.split(":")[0].strip(): float(line.split(":")[1])
               for line in result.stdout.splitlines() if "/self_filter/m" in line}
        assert box == {"/fusion/self_filter/min_x": -8.0, "/fusion/self_filter/min_y": -8.0,
                       "/fusion/self_filter/min_z": -3.0, "/fusion/self_filter/max_x": 8.0,
                       "/fusion/self_filter/max_y": 8.0, "/fusion/self_filter/max_z": 3.0}, \
            result.stdout


def test_row08_a_missing_or_malformed_corner_is_named_by_roslaunch():
    for args, named in ((["self_filter_min:=8 8 3"], "self_filter_max (missing"),
                        (["self_filter_max:=8 8 3"], "self_filter_min (missing"),
                        (["self_filter_min:=8 8", "self_filter_max:=1 1 1"], "three numbers"),
                        (["self_filter_min:=8 8 x", "self_filter_max:=1 1 1"], "three numbers"),
                        (["self_filter_min:=8 8 3", "self_filter_max:=8 1 1"], "zero size")):
        result = roslaunch("--nodes", *args)
        assert result.returncode == 1, args
        output = result.stdout + result.stderr
        assert named in output, output
        assert "Traceback" not in output and "IndexError" not in output, output


# Row 9 ------------------------------------------------------------------------------------------
def test_row09_a_remap_typo_is_refused_and_relative_topics_are_resolved(drive, raw_depth):
    result = bag_runner("--bag", drive, "--out", scratch("row09_typo"),
                        "left/image_rect:=/stereo/right/image_rect_color")
    assert result.returncode == 2
    assert "'left/image_rect' is no input or output name (did you mean left/image_rect_color?)" \
        in result.stderr, result.stderr
    out = scratch("row09_relative")
    result = bag_runner("--bag", drive, "--out", out, "--confidence",
                        "left/image_rect_color:=stereo/left/image_rect_color",
                        "left/camera_info:=stereo/left/camera_info",
                        "velodyne_points:=velodyne_points")
    assert result.returncode == 0, result.stderr
    assert pngs(out) == pngs(raw_depth)


# Row 10 -----------------------------------------------------------------------------------------
def test_row10_a_bag_that_is_no_bag_says_what_it_is(drive):
    random_bytes = recording_bags.random_file(os.path.join(SCRATCH, "random.bag"))
    empty = recording_bags.empty_file(os.path.join(SCRATCH, "empty.bag"))
    folder = os.path.join(SCRATCH, "a_folder")
    os.makedirs(folder, exist_ok=True)
    missing = os.path.join(SCRATCH, "missing.bag")
    truncated = batch_bags.truncated_copy(drive, os.path.join(SCRATCH, "truncated.bag"))
    for path, said in ((random_bytes, "not a ROS 1 bag"), (empty, "an empty file (0 bytes)"),
                       (folder, "a folder, not a bag file"), (missing, "no such file"),
                       (truncated, "rosbag reindex")):
        result = bag_runner("--bag", path, "--out", scratch("row10"))
        assert result.returncode == 1, path
        assert "cannot read bag %s: " % path in result.stderr
        assert said in result.stderr, result.stderr
        if path != truncated:
            assert "reindex" not in result.stderr, result.stderr


# Row 11 -----------------------------------------------------------------------------------------
def test_row11_an_empty_time_window_is_refused_before_any_work(drive):
    out = scratch("row11")
    result = bag_runner("--bag", drive, "--out", out, "--start", "100")
    assert result.returncode == 1
    assert "--start 100.000 s is past the end of the recording (0.558 s long)" in result.stderr, \
        result.stderr
    result = bag_runner("--bag", drive, "--out", out, "--end", "0")
    assert result.returncode == 2
    assert "--end 0: the window [start, end) is empty" in result.stderr
    result = bag_runner("--bag", drive, "--out", out, "--start", "0.1", "--end", "0.2")
    assert result.returncode == 1
    assert "no image set in the time window [0.100, 0.200) s" in result.stderr, result.stderr
    assert not os.path.exists(out)


# Row 12 -----------------------------------------------------------------------------------------
def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def bag_runners_under(pid):
    """The bag_runner processes of tasks (not --prepare) below process `pid`."""
    import psutil
    try:
        children = psutil.Process(pid).children(recursive=True)
    except psutil.NoSuchProcess:
        return []
    found = []
    for p in children:
        try:
            if p.name() == "bag_runner" and "--prepare" not in p.cmdline():
                found.append(p)
        except psutil.NoSuchProcess:
            continue
    return found


def test_row12_an_unreachable_scheduler_is_one_line():
    address = "tcp://127.0.0.1:%d" % free_port()
    result = batch("--out", scratch("row12_unreachable"), "--scheduler", address,
                   "--connect-timeout", "3", os.path.join(SCRATCH, "drive.bag"))
    assert result.returncode == 1
    assert "Traceback" not in result.stderr, result.stderr
    lines = [line for line in result.stderr.splitlines() if "cannot reach the scheduler" in line]
    assert len(lines) == 1 and address in lines[0], result.stderr


def test_row12_a_lost_scheduler_stops_the_batch_and_its_bag_runners(long_bag):
    port = free_port()
    address = "tcp://127.0.0.1:%d" % port
    logs = scratch("row12_logs")
    os.makedirs(logs)
    scheduler = subprocess.Popen(["dask-scheduler", "--port", str(port), "--no-dashboard"],
                                 stdout=open(os.path.join(logs, "scheduler.log"), "w"),
                                 stderr=subprocess.STDOUT, start_new_session=True)
    worker = subprocess.Popen(["dask-worker", address, "--nworkers", "1", "--nthreads", "1",
                               "--no-dashboard"],
                              stdout=open(os.path.join(logs, "worker.log"), "w"),
                              stderr=subprocess.STDOUT, start_new_session=True)
    out = scratch("row12_lost")
    try:
        proc = subprocess.Popen([sys.executable, LSF_BATCH, "--bag-runner", BAG_RUNNER,
                                 "--scheduler", address, "--out", out, long_bag],
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                universal_newlines=True)
        deadline = time.time() + DEADLINE
        while time.time() < deadline and proc.poll() is None and not bag_runners_under(worker.pid):
            time.sleep(0.05)
        assert bag_runners_under(worker.pid), "no task started"
        os.killpg(scheduler.pid, signal.SIGKILL)
        stdout, stderr = proc.communicate(timeout=DEADLINE)
        assert proc.returncode == 1, stderr
        assert "Traceback" not in stderr, stderr
        lost = [line for line in stderr.splitlines() if "lost the scheduler" in line]
        assert len(lost) == 1 and address in lost[0], stderr
        deadline = time.time() + 120
        while bag_runners_under(worker.pid) and time.time() < deadline:
            time.sleep(0.2)
        assert not bag_runners_under(worker.pid), "bag_runner still runs"
        written = len(pngs(os.path.join(out, "long")))
        # Nothing may write any more: a new PNG within 1 s fails at once.
        deadline = time.time() + 1.0
        while len(pngs(os.path.join(out, "long"))) == written and time.time() < deadline:
            time.sleep(0.05)
        assert len(pngs(os.path.join(out, "long"))) == written
    finally:
        for p in (worker, scheduler):
            try:
                os.killpg(p.pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
            p.wait()
    # The same command on a cluster that stays: everything, as bag_runner alone gives it.
    result = batch("--out", out, long_bag)
    assert result.returncode == 0, result.stderr
    alone = scratch("row12_alone")
    assert bag_runner("--bag", long_bag, "--out", alone).returncode == 0
    assert pngs(os.path.join(out, "long")) == pngs(alone)


# Row 13 -----------------------------------------------------------------------------------------
def test_row13_chunk_has_a_floor_and_tasks_a_limit(long_bag):
    result = batch("--out", scratch("row13"), "--chunk", "0.0001", long_bag, timeout=60)
    assert result.returncode == 2
    assert "--chunk 0.0001: chunks must be at least 0.1 s" in result.stderr, result.stderr
    result = batch("--out", scratch("row13"), "--chunk", "0.1", "--max-tasks", "3", long_bag,
                   timeout=60)
    assert result.returncode == 2
    assert re.search(r"\d+ tasks \(--chunk 0.1 over 1 bags\) is more than --max-tasks 3",
                     result.stderr), result.stderr
    assert "scheduler" not in result.stderr  # refused before a cluster started


# Row 14 -----------------------------------------------------------------------------------------
def test_row14_an_output_folder_that_cannot_be_written_is_refused_before_any_work(drive):
    parent = scratch("row14")
    os.makedirs(parent)
    os.chmod(parent, 0o555)
    out = os.path.join(parent, "out")
    command = [BAG_RUNNER, "--bag", drive, "--out", out]
    if os.geteuid() == 0:  # root writes anywhere: run as nobody
        command = ["setpriv", "--reuid=65534", "--regid=65534", "--clear-groups"] + command
    result = run(command)
    assert result.returncode == 1
    assert "cannot write in %s (output): cannot create it: Permission denied" % out \
        in result.stderr, result.stderr
    assert "image sets on" not in result.stderr  # before any work
    result = bag_runner("--bag", drive, "--out", drive + "_not_a_folder", "--frames-csv",
                        os.path.join(drive, "rows.csv"))
    assert result.returncode == 1
    assert "cannot write in %s (output)" % drive in result.stderr, result.stderr


# Row 15 -----------------------------------------------------------------------------------------
def test_row15_cloud_pcd_has_the_layout_of_points2_and_kitti_runner(drive):
    import cv2
    out = scratch("row15")
    result = bag_runner("--bag", drive, "--out", out, "--cloud", "--method", "lidar_bi")
    assert result.returncode == 0, result.stderr
    for name in pngs(out):
        pcd = os.path.join(out, "cloud", name[:-4] + ".pcd")
        with open(pcd, "rb") as f:
            header = {}
            for _ in range(11):
                key, _, value = f.readline().decode().strip().partition(" ")
                header[key] = value
        assert header["FIELDS"] == "x y z rgb", header
        depth = cv2.imread(os.path.join(out, name), cv2.IMREAD_UNCHANGED)
        assert int(header["POINTS"]) == int((depth > 0).sum())
