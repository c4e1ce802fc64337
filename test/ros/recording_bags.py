"""Recordings as users keep them, made at test time from a bag kitti_to_bag wrote (issue 33):
images recorded as sensor_msgs/CompressedImage (png or jpeg, as compressed_image_transport writes
them, on <topic>/compressed), and files that are no bag (random bytes, empty). Everything goes
into the caller's scratch folder (the build folder, ignored by git); nothing is committed."""

import os

IMAGE_TOPICS = ("/stereo/left/image_rect_color", "/stereo/right/image_rect_color")


def compressed_copy(src, dst, codec, quality=95):
    """`src` with every image of IMAGE_TOPICS replaced by a CompressedImage on <topic>/compressed:
    codec "png" (lossless) or "jpeg" (at `quality`), format as compressed_image_transport writes
    it ("bgr8; png compressed bgr8")."""
    import cv2
    import numpy as np
    import rosbag
    from sensor_msgs.msg import CompressedImage
    params = [cv2.IMWRITE_JPEG_QUALITY, quality] if codec == "jpeg" else []
    ext = ".jpg" if codec == "jpeg" else ".png"
    with rosbag.Bag(src) as bag, rosbag.Bag(dst, "w") as out:
        for topic, msg, t in bag.read_messages():
            if topic not in IMAGE_TOPICS:
                out.write(topic, msg, t)
                continue
            assert msg.encoding == "bgr8", msg.encoding
            pixels = np.frombuffer(msg.data, np.uint8).reshape(msg.height, msg.step)
            bgr = pixels[:, :msg.width * 3].reshape(msg.height, msg.width, 3)
            ok, data = cv2.imencode(ext, bgr, params)
            assert ok
            compressed = CompressedImage()
            compressed.header = msg.header
            compressed.format = "bgr8; %s compressed bgr8" % codec
            compressed.data = data.tobytes()
            out.write(topic + "/compressed", compressed, t)
    return dst


def random_file(path, size=4096, seed=33):
    """`size` random bytes: a file that is no bag."""
    import random
    rng = random.Random(seed)
    with open(path, "wb") as f:
        f.write(bytes(rng.getrandbits(8) for _ in range(size)))
    return path


def empty_file(path):
    open(path, "wb").close()
    return path


def dead_pid():
    """A process id that runs nothing (a child that has exited)."""
    pid = os.fork()
    if pid == 0:
        os._exit(0)
    os.waitpid(pid, 0)
    return pid
