#!/usr/bin/env python3
# Copyright wild_mvs authors.
"""Ends a bag reconstruction (launch/reconstruct_bag.launch): waits until the
bag has been played (no image for ~image_idle s after the first one) and the
depth node is idle (nothing pending in its diagnostics and no new depth view
for ~view_idle s), then calls the fusion node's ~save service and exits; the
launch file marks this node required, so everything shuts down after it."""
import sys
import time

import rospy
from diagnostic_msgs.msg import DiagnosticArray
from sensor_msgs.msg import Image
from wild_mvs.msg import DepthView
from wild_mvs.srv import SaveCloud


class Finisher:
    def __init__(self):
        self.first_image = None
        self.last_image = None
        self.last_view = time.monotonic()
        self.busy = True
        self.views = 0

    def on_image(self, _msg):
        now = time.monotonic()
        if self.first_image is None:
            self.first_image = now
        self.last_image = now

    def on_view(self, _msg):
        self.last_view = time.monotonic()
        self.views += 1

    def on_diag(self, msg):
        for st in msg.status:
            if "depth_node" not in st.name:
                continue
            vals = {kv.key: kv.value for kv in st.values}
            try:
                self.busy = (int(vals.get("reconstructions pending", "0")) > 0 or
                             int(vals.get("input queue length", "0")) > 0 or
                             int(vals.get("keyframes waiting", "0")) > 0)
            except ValueError:
                pass


def main():
    rospy.init_node("finish_when_idle")
    image_topic = rospy.get_param("~image", "/camera/image_raw")
    view_topic = rospy.get_param("~views", "/depth_node/depth_view")
    service = rospy.get_param("~save_service", "/fusion_node/save")
    output = rospy.get_param("~output", "")
    image_idle = rospy.get_param("~image_idle", 3.0)
    view_idle = rospy.get_param("~view_idle", 4.0)
    timeout = rospy.get_param("~timeout", 3600.0)
    f = Finisher()
    rospy.Subscriber(image_topic, Image, f.on_image, queue_size=50)
    rospy.Subscriber(view_topic, DepthView, f.on_view, queue_size=50)
    rospy.Subscriber("/diagnostics", DiagnosticArray, f.on_diag, queue_size=10)
    start = time.monotonic()
    while not rospy.is_shutdown():
        time.sleep(0.5)
        now = time.monotonic()
        if now - start > timeout:
            rospy.logerr("finish_when_idle: timeout after %.0f s", timeout)
            break
        if f.last_image is None or now - f.last_image < image_idle:
            continue
        if f.busy or now - f.last_view < view_idle:
            continue
        break
    if rospy.is_shutdown():
        return 1
    rospy.wait_for_service(service, timeout=30)
    save = rospy.ServiceProxy(service, SaveCloud)
    res = save(output)
    played = (f.last_image - f.first_image) if f.first_image else 0.0
    if res.success:
        rospy.loginfo("finish_when_idle: %d depth views, saved %d points to %s "
                      "(%.1f s after the first image)", f.views, res.num_points,
                      res.message, time.monotonic() - start - 0.0)
        print("wild_mvs: saved %d points to %s; %d depth views; bag played in "
              "%.1f s; total %.1f s" % (res.num_points, res.message, f.views,
                                        played, time.monotonic() - (f.first_image or start)))
        return 0
    rospy.logerr("finish_when_idle: save failed: %s", res.message)
    return 1


if __name__ == "__main__":
    sys.exit(main())
