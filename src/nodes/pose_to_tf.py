#!/usr/bin/env python3
# Copyright wild_mvs authors.
"""Relays a localisation topic to /tf, so that the depth node (pose from tf)
works with any pose source: a bag or a SLAM system that publishes
geometry_msgs/PoseStamped, PoseWithCovarianceStamped, TransformStamped or
nav_msgs/Odometry instead of tf (EuRoC's /vicon/firefly_sbx/firefly_sbx,
/leica, an odometry topic, ...).

  rosrun wild_mvs pose_to_tf.py pose:=/vicon/firefly_sbx/firefly_sbx _type:=TransformStamped _child_frame:=body

Parameters:
  ~type         PoseStamped | PoseWithCovarianceStamped | TransformStamped | Odometry
  ~parent_frame parent frame of the transform; default: the message's header frame
  ~child_frame  child frame; default: the message's child_frame_id
                (TransformStamped, Odometry), else "body"
Stamps pass through unchanged; a leading '/' of a frame id is stripped (tf2
rejects it). The camera then hangs below the child frame through
/tf_static (e.g. `rosrun tf2_ros static_transform_publisher ... body cam0`).
"""
import sys

import rospy
import tf2_ros
from geometry_msgs.msg import (PoseStamped, PoseWithCovarianceStamped,
                               TransformStamped)
from nav_msgs.msg import Odometry

TYPES = {
    "PoseStamped": PoseStamped,
    "PoseWithCovarianceStamped": PoseWithCovarianceStamped,
    "TransformStamped": TransformStamped,
    "Odometry": Odometry,
}


def strip(frame):
    return frame.lstrip("/")


def main():
    rospy.init_node("pose_to_tf")
    kind = rospy.get_param("~type", "PoseStamped")
    if kind not in TYPES:
        rospy.logfatal("pose_to_tf: ~type '%s' must be one of %s", kind,
                       ", ".join(sorted(TYPES)))
        return 2
    parent = strip(rospy.get_param("~parent_frame", ""))
    child = strip(rospy.get_param("~child_frame", ""))
    broadcaster = tf2_ros.TransformBroadcaster()

    def on_msg(msg):
        t = TransformStamped()
        t.header.stamp = msg.header.stamp  # unchanged
        t.header.frame_id = parent or strip(msg.header.frame_id)
        if kind == "TransformStamped":
            t.child_frame_id = child or strip(msg.child_frame_id) or "body"
            t.transform = msg.transform
        else:
            if kind == "Odometry":
                t.child_frame_id = child or strip(msg.child_frame_id) or "body"
                pose = msg.pose.pose
            elif kind == "PoseWithCovarianceStamped":
                t.child_frame_id = child or "body"
                pose = msg.pose.pose
            else:
                t.child_frame_id = child or "body"
                pose = msg.pose
            t.transform.translation.x = pose.position.x
            t.transform.translation.y = pose.position.y
            t.transform.translation.z = pose.position.z
            t.transform.rotation = pose.orientation
        if not t.header.frame_id:
            rospy.logerr_throttle(5, "pose_to_tf: %s has an empty frame_id "
                                  "(set ~parent_frame)", rospy.resolve_name("pose"))
            return
        broadcaster.sendTransform(t)

    rospy.Subscriber("pose", TYPES[kind], on_msg, queue_size=100)
    rospy.spin()
    return 0


if __name__ == "__main__":
    sys.exit(main())
