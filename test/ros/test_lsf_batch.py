"""bag_runner and lsf_batch on small KITTI bags (kitti_to_bag of two frames each; pytest, run by
`catkin_make run_tests`). lsf_batch runs on its embedded LocalCluster of 2 worker processes:
  - 3 bags: every frame present, depth PNGs byte-identical to serial bag_runner on each bag;
  - a worker process killed while its bag_runner runs: the run still completes, nothing missing;
  - a bag in time chunks (--chunk) gives the files of the whole bag;
  - re-running does only what is missing (bag_runner --resume and lsf_batch);
  - a truncated bag, a bag without the camera topics and a bag without the LiDAR -> camera TF are
    named, with a non-zero exit status, while the other bags finish;
  - a rig the tests have no bag of (ZED + Velodyne topic names, sweeps recorded after the images):
    with remaps the same depth as the KITTI bag.
Missing data fails under CI=true and skips otherwise. No timing is asserted."""

import csv
import glob
import os
import signal
import subprocess
import sys
import time

import psutil
import pytest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import batch_bags  # noqa: E402
import bag_tool_setup  # noqa: E402
from bag_tool_setup import long_bag_fixture  # noqa: E402,F401 (pytest fixtures)
from bag_tool_setup import (BAG_RUNNER, DEADLINE, LSF_BATCH, SCRATCH, SOURCE,  # noqa: E402
                            batch, run)

FRAMES = [bag_tool_setup.TWO_FRAMES, ["0000000010", "0000000015"],
          ["0000000020", "0000000025"]]


def setup_module():
    bag_tool_setup.prepare()


def pngs(folder):
    """{path relative to `folder`: bytes} of the PNGs under `folder`, sub-folders included."""
    return bag_tool_setup.pngs(folder, recursive=True)


def rows(folder):
    """frames.csv without the timings: stamp, status, reason, sweep stamp, coverage, rings."""
    with open(os.path.join(folder, "frames.csv")) as f:
        return [(r["stamp"], r["status"], r["reason"], r["sweep_stamp"], r["coverage"],
                 r["ring_method"]) for r in csv.DictReader(f)]


@pytest.fixture(scope="module")
def bags():
    return [bag_tool_setup.kitti_bag("drive%d" % i, frames) for i, frames in enumerate(FRAMES)]


@pytest.fixture(scope="module")
def serial(bags):
    """bag_runner on each bag alone."""
    out = {}
    for bag in bags:
        name = os.path.basename(bag)[:-4]
        folder = os.path.join(SCRATCH, "serial", name)
        result = run([BAG_RUNNER, "--bag", bag, "--out", folder])
        assert result.returncode == 0, result.stderr
        out[name] = folder
    return out


def test_bag_runner_writes_a_named_png_and_row_per_set(bags, serial):
    for name, folder in serial.items():
        files = pngs(folder)
        assert len(files) == 2, name
        table = rows(folder)
        assert [r[1] for r in table] == ["ok", "ok"]
        assert sorted(files) == sorted(r[0] + ".png" for r in table)
        for stamp in (r[0] for r in table):
            sec, nsec = stamp.split(".")
            assert len(nsec) == 9


def test_bag_runner_optional_outputs_and_output_bag(bags, serial):
    import rosbag
    folder = os.path.join(SCRATCH, "extras")
    out_bag = os.path.join(SCRATCH, "fused.bag")
    result = run([BAG_RUNNER, "--bag", bags[0], "--out", folder, "--disparity", "--confidence",
                  "--cloud", "--out-bag", out_bag])
    assert result.returncode == 0, result.stderr
    name = os.path.basename(bags[0])[:-4]
    stamps = [r[0] for r in rows(serial[name])]
    depth = {p: b for p, b in pngs(folder).items() if os.sep not in p}
    assert depth == pngs(serial[name])
    for sub, ext in (("disparity", ".png"), ("confidence", ".png"), ("cloud", ".pcd")):
        assert sorted(os.listdir(os.path.join(folder, sub))) == [s + ext for s in stamps], sub
    with rosbag.Bag(bags[0]) as bag:
        left = {"%d.%09d" % (m.header.stamp.secs, m.header.stamp.nsecs): t
                for _, m, t in bag.read_messages(["/stereo/left/image_rect_color"])}
    with rosbag.Bag(out_bag) as bag:
        topics = bag.get_type_and_topic_info().topics
        for topic in ("/fusion/depth/image_rect", "/fusion/depth/camera_info", "/fusion/disparity",
                      "/fusion/points2", "/fusion/lidar_disparity", "/fusion/confidence"):
            assert topics[topic].message_count == 2, topic
        for _, msg, t in bag.read_messages(["/fusion/depth/image_rect"]):
            stamp = "%d.%09d" % (msg.header.stamp.secs, msg.header.stamp.nsecs)
            assert stamp in stamps
            assert t == left[stamp]  # at the input's record time
            assert msg.encoding == "32FC1" and msg.header.frame_id == "left_camera_optical_frame"


def test_batch_of_three_bags_equals_serial_bag_runner(bags, serial):
    out = os.path.join(SCRATCH, "batch")
    result = batch("--out", out, os.path.join(SCRATCH, "drive?.bag"))
    assert result.returncode == 0, result.stderr
    for name, folder in serial.items():
        assert pngs(os.path.join(out, name)) == pngs(folder), name
        assert rows(os.path.join(out, name)) == rows(folder), name
    assert "frames/s" in result.stdout


def test_a_killed_worker_still_completes(bags, serial):
    out = os.path.join(SCRATCH, "killed")
    proc = subprocess.Popen([sys.executable, LSF_BATCH, "--bag-runner", BAG_RUNNER, "--workers",
                             "2", "--out", out] + bags, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, universal_newlines=True)
    killed = None
    deadline = time.time() + DEADLINE
    while killed is None and time.time() < deadline and proc.poll() is None:
        for child in psutil.Process(proc.pid).children(recursive=True):
            try:
                if child.name() == "bag_runner":
                    worker = child.parent()  # the dask worker process running the task
                    worker.send_signal(signal.SIGKILL)
                    killed = worker.pid
                    break
            except psutil.NoSuchProcess:
                continue
        time.sleep(0.01)
    stdout, stderr = proc.communicate(timeout=DEADLINE)
    assert killed is not None, "no bag_runner seen to kill the worker of"
    assert proc.returncode == 0, stderr
    for name, folder in serial.items():
        assert pngs(os.path.join(out, name)) == pngs(folder), name
        assert [r[1] for r in rows(os.path.join(out, name))] == ["ok", "ok"]


def test_chunked_equals_whole(long_bag):
    whole = os.path.join(SCRATCH, "whole")
    chunked = os.path.join(SCRATCH, "chunked")
    for out, extra in ((whole, []), (chunked, ["--chunk", "0.25"])):
        result = batch("--out", out, "--method", "lidar_bi", *extra, long_bag)
        assert result.returncode == 0, result.stderr
    assert len(glob.glob(os.path.join(chunked, "long", ".chunks", "*.csv"))) == 4
    assert len(pngs(os.path.join(whole, "long"))) == 9
    assert pngs(os.path.join(chunked, "long")) == pngs(os.path.join(whole, "long"))
    assert rows(os.path.join(chunked, "long")) == rows(os.path.join(whole, "long"))


def test_resume_does_only_the_rest(long_bag):
    out = os.path.join(SCRATCH, "resume")
    args = ["--out", out, "--method", "lidar_bi", "--chunk", "0.25", long_bag]
    assert batch(*args).returncode == 0
    folder = os.path.join(out, "long")
    before = {p: os.stat(os.path.join(folder, p)).st_mtime_ns for p in pngs(folder)}
    complete = pngs(folder)
    # Nothing missing: no task runs.
    result = batch(*args)
    assert result.returncode == 0, result.stderr
    assert "(4 already done)" in result.stderr
    # One chunk's rows and one of its PNGs lost: only that chunk runs, only that PNG is written.
    first_chunk = sorted(glob.glob(os.path.join(folder, ".chunks", "*.csv")))[0]
    os.remove(first_chunk)
    lost = sorted(before)[0]
    os.remove(os.path.join(folder, lost))
    result = batch(*args)
    assert result.returncode == 0, result.stderr
    assert "(3 already done)" in result.stderr
    assert pngs(folder) == complete
    for path, mtime in before.items():
        if path != lost:
            assert os.stat(os.path.join(folder, path)).st_mtime_ns == mtime, path
    assert [r[1] for r in rows(folder)] == ["ok"] * 9
    # bag_runner --resume alone: the same.
    os.remove(os.path.join(folder, lost))
    result = run([BAG_RUNNER, "--bag", long_bag, "--out", folder, "--method", "lidar_bi",
                  "--resume"])
    assert result.returncode == 0, result.stderr
    assert pngs(folder) == complete
    assert [r[1] for r in rows(folder)] == ["ok"] * 9


def test_bad_bags_are_named_and_the_others_finish(bags, serial):
    truncated = batch_bags.truncated_copy(bags[0], os.path.join(SCRATCH, "truncated.bag"))
    no_camera = batch_bags.rewrite_bag(bags[1], os.path.join(SCRATCH, "no_camera.bag"),
                                       drop=[t for t in batch_bags.ZED_TOPICS if "stereo" in t])
    result = run([BAG_RUNNER, "--bag", truncated, "--out", os.path.join(SCRATCH, "t")])
    assert result.returncode == 1
    assert "cannot read bag " + truncated in result.stderr
    result = run([BAG_RUNNER, "--bag", no_camera, "--out", os.path.join(SCRATCH, "n")])
    assert result.returncode == 1
    assert "no messages on /stereo/left/image_rect_color" in result.stderr
    assert "left/image_rect_color:=" in result.stderr

    out = os.path.join(SCRATCH, "bad")
    result = batch("--out", out, truncated, no_camera, bags[2])
    assert result.returncode == 1
    assert truncated + ": " in result.stderr and "cannot read bag" in result.stderr
    assert no_camera + ": " in result.stderr
    name = os.path.basename(bags[2])[:-4]
    assert pngs(os.path.join(out, name)) == pngs(serial[name])


def test_missing_transform_fails_every_set_by_name(bags):
    import rosbag
    src, dst = bags[0], os.path.join(SCRATCH, "no_tf.bag")
    with rosbag.Bag(src) as bag, rosbag.Bag(dst, "w") as out:
        for topic, msg, t, header in bag.read_messages(return_connection_header=True):
            if topic == "/tf_static":
                for transform in msg.transforms:
                    if transform.header.frame_id == "velodyne":
                        transform.header.frame_id = "imu_link"  # no velodyne -> camera path
            out.write(topic, msg, t, connection_header=header)
    folder = os.path.join(SCRATCH, "no_tf")
    result = run([BAG_RUNNER, "--bag", dst, "--out", folder])
    assert result.returncode == 1
    table = rows(folder)
    assert [r[1] for r in table] == ["failed", "failed"]
    assert all("no transform from 'velodyne'" in r[2] for r in table)
    for stamp in (r[0] for r in table):
        assert stamp in result.stderr
    assert pngs(folder) == {}


def test_zed_velodyne_topics_with_late_sweeps(bags, serial):
    zed = batch_bags.rewrite_bag(bags[0], os.path.join(SCRATCH, "zed_rig.bag"),
                                 topics=batch_bags.ZED_TOPICS, sweep_delay=0.08)
    folder = os.path.join(SCRATCH, "zed", "zed_rig")
    result = run([BAG_RUNNER, "--bag", zed, "--out", folder] + batch_bags.ZED_REMAPS)
    assert result.returncode == 0, result.stderr
    name = os.path.basename(bags[0])[:-4]
    assert pngs(folder) == pngs(serial[name])
    # Without the remaps the missing topics are named.
    result = run([BAG_RUNNER, "--bag", zed, "--out", os.path.join(SCRATCH, "zed_plain")])
    assert result.returncode == 1
    assert "/zed/zed_node/left/image_rect_color" in result.stderr
    # lsf_batch passes the remaps on.
    out = os.path.join(SCRATCH, "zed_batch")
    result = batch("--out", out, zed, *batch_bags.ZED_REMAPS)
    assert result.returncode == 0, result.stderr
    assert pngs(os.path.join(out, "zed_rig")) == pngs(serial[name])


def test_node_params_file_and_approximate_sync(bags):
    outputs = []
    for i, extra in enumerate(([], ["--node-params", os.path.join(SOURCE, "config",
                                                                    "fusion_node.yaml")],
                               ["--approximate-sync"])):
        folder = os.path.join(SCRATCH, "node_params%d" % i)
        result = run([BAG_RUNNER, "--bag", bags[1], "--out", folder, "--method", "lidar_bi"] +
                     extra)
        assert result.returncode == 0, result.stderr
        outputs.append(pngs(folder))
    assert len(outputs[0]) == 2
    assert outputs[1] == outputs[0] and outputs[2] == outputs[0]
    bad = os.path.join(SCRATCH, "bad_node_params.yaml")
    with open(bad, "w") as f:
        f.write("approximate_sync: maybe\n")
    result = run([BAG_RUNNER, "--bag", bags[1], "--out", os.path.join(SCRATCH, "bad_np"),
                  "--node-params", bad])
    assert result.returncode == 1
    # The one wording of the YAML reader (io/param_yaml_reader.h): the file, the key, the rule.
    assert "params YAML " + bad + ": key 'approximate_sync' must be true or false" in result.stderr
