"""Small recorded drives for the tests of bag_runner and lsf_batch (test_lsf_batch.py): KITTI
frames of the sample drive through kitti_to_bag, and rewrites of such a bag into what other rigs
record (ZED + Velodyne topic names, sweeps recorded after the images, a bag without camera
topics, a truncated bag). Everything goes into a scratch folder; nothing of the data is kept."""

import os
import shutil
import subprocess

DATE = "kitti_raw/2011_09_26"
DRIVE = "2011_09_26_drive_0009_sync"

ZED_TOPICS = {
    "/stereo/left/image_rect_color": "/zed/zed_node/left/image_rect_color",
    "/stereo/left/camera_info": "/zed/zed_node/left/camera_info",
    "/stereo/right/image_rect_color": "/zed/zed_node/right/image_rect_color",
    "/stereo/right/camera_info": "/zed/zed_node/right/camera_info",
    "/velodyne_points": "/vls128/velodyne_points",
}
# bag_runner / lsf_batch remaps for a bag with the ZED_TOPICS.
ZED_REMAPS = ["left/image_rect_color:=/zed/zed_node/left/image_rect_color",
              "left/camera_info:=/zed/zed_node/left/camera_info",
              "right/image_rect_color:=/zed/zed_node/right/image_rect_color",
              "right/camera_info:=/zed/zed_node/right/camera_info",
              "velodyne_points:=/vls128/velodyne_points"]


def subset_drive(data_dir, scratch, frames):
    """A KITTI date folder under `scratch` whose drive holds only `frames` (symbolic links)."""
    src_date = os.path.join(data_dir, DATE)
    src = os.path.join(src_date, DRIVE)
    date = os.path.join(scratch, "subset_" + "_".join(frames), "2011_09_26")
    drive = os.path.join(date, DRIVE)
    shutil.rmtree(os.path.dirname(date), ignore_errors=True)
    os.makedirs(date)
    for calib in ("calib_cam_to_cam.txt", "calib_velo_to_cam.txt"):
        os.symlink(os.path.join(src_date, calib), os.path.join(date, calib))
    for sensor in ("image_02", "image_03", "velodyne_points"):
        os.makedirs(os.path.join(drive, sensor, "data"))
        for name in os.listdir(os.path.join(src, sensor)):
            if name.endswith(".txt"):
                os.symlink(os.path.join(src, sensor, name), os.path.join(drive, sensor, name))
        ext = ".bin" if sensor == "velodyne_points" else ".png"
        for frame in frames:
            os.symlink(os.path.join(src, sensor, "data", frame + ext),
                       os.path.join(drive, sensor, "data", frame + ext))
    return drive


def kitti_bag(kitti_to_bag, data_dir, scratch, frames, path, extra=()):
    """kitti_to_bag of `frames` into `path`."""
    drive = subset_drive(data_dir, scratch, frames)
    subprocess.run([kitti_to_bag, "--kitti-raw", drive, "--out", path] + list(extra), check=True,
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return path


def rewrite_bag(src, dst, topics=None, drop=(), sweep_delay=0.0):
    """Copies `src` into `dst`: topics renamed by `topics`, those in `drop` left out, sweeps
    recorded `sweep_delay` seconds after their stamp (a driver that publishes late)."""
    import rosbag
    import rospy
    topics = topics or {}
    with rosbag.Bag(src) as bag, rosbag.Bag(dst, "w") as out:
        for topic, msg, t, header in bag.read_messages(return_connection_header=True):
            if topic in drop:
                continue
            if topic == "/velodyne_points" and sweep_delay:
                t = msg.header.stamp + rospy.Duration.from_sec(sweep_delay)
            out.write(topics.get(topic, topic), msg, t, connection_header=header)
    return dst


def truncated_copy(src, dst, fraction=0.5):
    """The first `fraction` of the bytes of `src`: a recording cut off (no index)."""
    with open(src, "rb") as f:
        data = f.read()
    with open(dst, "wb") as f:
        f.write(data[:int(len(data) * fraction)])
    return dst
