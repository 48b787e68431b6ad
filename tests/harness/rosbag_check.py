#!/usr/bin/env python3
"""The bag `vobench render --format rosbag` writes, read by Debian's python3-rosbag.

Renders a short hallway scenario and checks, with ROS's own reader: the topics and their types;
every image (mono8) equal to the KITTI export's PNG of the same frame, byte for byte; the depth
topic equal to the depth PNGs; camera_info's K and P equal to calib.txt's P0 / P1; every stamp
19 digits, the same on images, camera_info, depth and ground truth, and equal to the simulation
epoch plus times.txt; the IMU messages between and up to the frames, their covariances those of
the scenario's noise densities. Usage: rosbag_check.py VOBENCH SOURCE_DIR. Exit 0: passed,
1: failed, 77: skipped (no python3-rosbag or python3-opencv, or vobench built without bags).
"""
import os
import shutil
import subprocess
import sys
import tempfile

try:
    import cv2
    import numpy as np
    import rosbag
except ImportError as e:
    print(f"skipped: {e} (install python3-rosbag python3-opencv)")
    sys.exit(77)

EPOCH_NS = 1767225600000000000  # harness/dataset/writer.h kSimulationEpochNs
failures = []


def check(ok, what):
    if not ok:
        failures.append(what)
        print("FAIL:", what)


def main():
    vobench, source = sys.argv[1], sys.argv[2]
    tmp = tempfile.mkdtemp(prefix="vobench_rosbag_check_")
    try:
        scenario = os.path.join(tmp, "short.yaml")
        with open(scenario, "w") as f:
            f.write(f"name: short\nscene: {source}/scenes/hallway_l.xml\n"
                    "path:\n  - [0, 0]\n  - [0.5, 0]\n")
        out = os.path.join(tmp, "short")
        r = subprocess.run([vobench, "render", scenario, "--format", "rosbag", "--out", out, "-q"],
                           capture_output=True, text=True)
        if r.returncode != 0 and "without ROS bag support" in r.stderr:
            print("skipped: vobench built without ROS bag support")
            return 77
        check(r.returncode == 0, "render exit code " + str(r.returncode) + ": " + r.stderr)
        bag = rosbag.Bag(os.path.join(out, "short.bag"))
        info = bag.get_type_and_topic_info()
        expected = {
            "/cam0/image_raw": "sensor_msgs/Image", "/cam1/image_raw": "sensor_msgs/Image",
            "/cam0/camera_info": "sensor_msgs/CameraInfo",
            "/cam1/camera_info": "sensor_msgs/CameraInfo",
            "/cam0/depth/image_raw": "sensor_msgs/Image", "/imu0": "sensor_msgs/Imu",
            "/groundtruth/cam0": "geometry_msgs/TransformStamped",
            "/groundtruth/imu0": "geometry_msgs/TransformStamped"}
        for topic, type_name in expected.items():
            check(topic in info.topics and info.topics[topic].msg_type == type_name,
                  f"{topic} of type {type_name}")
        times = [float(line) for line in open(os.path.join(out, "times.txt")) if line.strip()]
        frame_ns = [EPOCH_NS + int(round(t * 1e9)) for t in times]
        calib = {}
        for line in open(os.path.join(out, "calib.txt")):
            key, *values = line.split()
            calib[key.rstrip(":")] = [float(v) for v in values]
        msgs = {t: [] for t in expected}
        for topic, msg, t in bag.read_messages():
            check(msg.header.stamp == t, f"{topic}: bag time = header stamp")
            msgs[topic].append(msg)
        for cam, folder in ((0, "image_0"), (1, "image_1")):
            images = msgs[f"/cam{cam}/image_raw"]
            check(len(images) == len(times), f"cam{cam}: {len(images)} images, {len(times)} frames")
            for i, m in enumerate(images):
                png = cv2.imread(os.path.join(out, folder, "%06d.png" % i), cv2.IMREAD_UNCHANGED)
                img = np.frombuffer(m.data, np.uint8).reshape(m.height, m.step)[:, :m.width]
                check(m.encoding == "mono8" and m.header.frame_id == f"cam{cam}",
                      f"cam{cam} frame {i}: mono8, frame_id cam{cam}")
                check(png is not None and png.shape == img.shape and (png == img).all(),
                      f"cam{cam} frame {i}: image equals {folder}/%06d.png" % i)
                check(m.header.stamp.to_nsec() == frame_ns[i] and len(str(frame_ns[i])) == 19,
                      f"cam{cam} frame {i}: stamp {m.header.stamp.to_nsec()} = {frame_ns[i]}")
            for i, c in enumerate(msgs[f"/cam{cam}/camera_info"]):
                p = calib[f"P{cam}"]
                check(list(c.P) == p and list(c.K) == [p[0], 0, p[2], 0, p[5], p[6], 0, 0, 1] and
                      c.distortion_model == "plumb_bob" and list(c.D) == [0.0] * 5 and
                      list(c.R) == [1, 0, 0, 0, 1, 0, 0, 0, 1],
                      f"cam{cam} camera_info {i}: K, P = calib.txt P{cam}, D = 0, R = I")
                check(c.header.stamp.to_nsec() == frame_ns[i], f"camera_info {i} stamp")
        for i, m in enumerate(msgs["/cam0/depth/image_raw"]):
            png = cv2.imread(os.path.join(out, "depth", "%06d.png" % i), cv2.IMREAD_UNCHANGED)
            d = np.frombuffer(m.data, "<u2").reshape(m.height, m.width)
            check(m.encoding == "16UC1" and (png == d).all(), f"depth {i} equals depth/%06d.png" % i)
        gt = msgs["/groundtruth/cam0"]
        check([g.header.stamp.to_nsec() for g in gt] == frame_ns, "ground truth at the frame stamps")
        check(all(g.header.frame_id == "world" and g.child_frame_id == "cam0" for g in gt),
              "ground truth: world -> cam0")
        imu = msgs["/imu0"]
        stamps = [m.header.stamp.to_nsec() for m in imu]
        check(len(imu) > 10 * len(times) and stamps == sorted(stamps) and
              stamps[-1] <= frame_ns[-1], f"{len(imu)} IMU samples up to the last frame")
        rate = 1e9 / np.median(np.diff(stamps))
        gyro_density, accel_density = 0.004 * np.pi / 180.0, 100e-6 * 9.80665  # sim/scenario.h
        m = imu[0]
        check(m.header.frame_id == "imu4" and m.orientation_covariance[0] == -1.0, "imu4, no orientation")
        check(abs(m.angular_velocity_covariance[0] - gyro_density ** 2 * rate) < 1e-12 and
              abs(m.linear_acceleration_covariance[4] - accel_density ** 2 * rate) < 1e-9,
              "IMU covariances = density^2 * rate")
        check(np.median([m.linear_acceleration.z for m in imu]) > 9.0 or
              np.median([abs(m.linear_acceleration.x) + abs(m.linear_acceleration.y) +
                         abs(m.linear_acceleration.z) for m in imu]) > 9.0, "gravity in the accelerometer")
    finally:
        shutil.rmtree(tmp)
    print("rosbag_check:", "FAILED" if failures else "passed", f"({len(failures)} failures)")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
