#!/usr/bin/env python3
# Copyright wild_mvs authors.
"""Publishes a sensor_msgs/CameraInfo beside an image topic, one per image
with the image's header (stamp and frame unchanged), for bags and drivers
that record images without camera_info (EuRoC MAV bags, many USB cameras).

  rosrun wild_mvs camera_info_publisher.py image:=/cam0/image_raw _file:=cam0.yaml

The calibration comes from ~file, a YAML file in the ROS calibration format
(camera_calibration_parsers: image_width, image_height, distortion_model,
camera_matrix.data, distortion_coefficients.data, optional projection_matrix
and rectification_matrix), or from parameters: ~width, ~height,
~intrinsics [fx, fy, cx, cy] (ROS pixel convention: top-left pixel centre at
0, 0), ~distortion_model (plumb_bob), ~distortion [k1, k2, p1, p2, k3].
Published on ~camera_info (default: <image namespace>/camera_info, the
image_transport convention the depth node listens on).
"""
import sys

import rospy
import yaml
from sensor_msgs.msg import CameraInfo, Image


def load_info():
    info = CameraInfo()
    path = rospy.get_param("~file", "")
    if path:
        try:
            with open(path) as f:
                c = yaml.safe_load(f)
            info.width = int(c["image_width"])
            info.height = int(c["image_height"])
            info.distortion_model = c.get("distortion_model", "plumb_bob")
            info.K = [float(v) for v in c["camera_matrix"]["data"]]
            info.D = [float(v) for v in c.get("distortion_coefficients", {}).get("data", [])]
            info.R = [float(v) for v in c.get("rectification_matrix", {}).get(
                "data", [1, 0, 0, 0, 1, 0, 0, 0, 1])]
            P = c.get("projection_matrix", {}).get("data")
        except (OSError, KeyError, TypeError, ValueError, yaml.YAMLError) as e:
            raise RuntimeError("%s: not a ROS camera calibration file: %s" % (path, e))
        if len(info.K) != 9:
            raise RuntimeError("%s: camera_matrix must have 9 values" % path)
    else:
        fx, fy, cx, cy = [float(v) for v in rospy.get_param("~intrinsics")]
        info.width = int(rospy.get_param("~width"))
        info.height = int(rospy.get_param("~height"))
        info.distortion_model = rospy.get_param("~distortion_model", "plumb_bob")
        info.D = [float(v) for v in rospy.get_param("~distortion", [0.0] * 5)]
        info.K = [fx, 0, cx, 0, fy, cy, 0, 0, 1]
        info.R = [1, 0, 0, 0, 1, 0, 0, 0, 1]
        P = None
    K = info.K
    info.P = [float(v) for v in P] if P else [K[0], 0, K[2], 0, 0, K[4], K[5], 0, 0, 0, 1, 0]
    return info


def main():
    rospy.init_node("camera_info_publisher")
    try:
        info = load_info()
    except (RuntimeError, KeyError, ValueError) as e:
        rospy.logfatal("camera_info_publisher: %s", e)
        return 2
    image = rospy.resolve_name("image")
    topic = rospy.get_param("~camera_info", image.rsplit("/", 1)[0] + "/camera_info")
    pub = rospy.Publisher(topic, CameraInfo, queue_size=20)

    def on_image(msg):
        if msg.width != info.width or msg.height != info.height:
            rospy.logerr_throttle(5, "camera_info_publisher: %s is %dx%d, the calibration %dx%d",
                                  image, msg.width, msg.height, info.width, info.height)
            return
        info.header = msg.header  # stamp and frame unchanged
        pub.publish(info)

    rospy.Subscriber(image, Image, on_image, queue_size=20)
    rospy.loginfo("camera_info_publisher: %s -> %s", image, topic)
    rospy.spin()
    return 0


if __name__ == "__main__":
    sys.exit(main())
