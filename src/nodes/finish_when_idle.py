#!/usr/bin/env python3
# Copyright wild_mvs authors.
"""Ends a bag reconstruction (launch/reconstruct_bag.launch) whatever the
topics are called: it only reads /diagnostics. Once the depth node's
"frames received" went above 0 and then stopped increasing for ~image_idle
s (the bag is played), its "reconstructions pending", "input queue length",
"keyframes waiting" and "revisions to come" are 0, the fusion node's "input queue length" and
"views waiting for order" are 0, and no counter of either node changed for
~view_idle s, it calls the fusion node's ~save service and exits; the launch
file marks this node required, so the whole launch ends after it.

All waiting uses wall (monotonic) time: with use_sim_time the /clock stops
when the bag ends, so rospy.sleep / rospy.Timer / rospy.Time are not used
for the idle logic.

Parameters: ~depth_status, ~fusion_status (substrings of the diagnostic
status names, default depth_node / fusion_node), ~save_service
(/fusion_node/save), ~output (path passed to the service, "" = the fusion
node's output_path), ~image_idle (3 s), ~view_idle (4 s), ~stale (20 s: the
diagnostics stopped coming while everything was idle: finish too),
~timeout (s, 0 = none; default 0)."""
import sys
import threading
import time

import rospy
from diagnostic_msgs.msg import DiagnosticArray
from wild_mvs.srv import SaveCloud

DEPTH_BUSY = ("reconstructions pending", "input queue length", "keyframes waiting",
              "revisions to come")
FUSION_BUSY = ("input queue length", "views waiting for order")
DEPTH_COUNTERS = ("frames received", "keyframes created", "depth maps",
                  "depth maps revised", "reconstructions failed")
FUSION_COUNTERS = ("views received", "views fused")


def _int(vals, key):
    try:
        return int(float(vals.get(key, "0")))
    except ValueError:
        return 0


class Finisher:
    def __init__(self, depth_status, fusion_status):
        self.depth_status = depth_status
        self.fusion_status = fusion_status
        self.lock = threading.Lock()
        self.depth = None          # latest key -> int of the depth node
        self.fusion = None         # ... and of the fusion node
        self.first_frame = None    # monotonic time "frames received" went > 0
        self.last_frame = None     # ... and last increased
        self.last_change = time.monotonic()  # any counter changed
        self.last_diag = None

    def on_diag(self, msg):
        now = time.monotonic()
        with self.lock:
            for st in msg.status:
                vals = {kv.key: kv.value for kv in st.values}
                if self.depth_status in st.name and "frames received" in vals:
                    new = {k: _int(vals, k) for k in DEPTH_COUNTERS + DEPTH_BUSY}
                    old = self.depth or {}
                    if new["frames received"] > old.get("frames received", 0):
                        if self.first_frame is None:
                            self.first_frame = now
                        self.last_frame = now
                    if any(new[k] != old.get(k) for k in DEPTH_COUNTERS):
                        self.last_change = now
                    self.depth = new
                    self.last_diag = now
                elif self.fusion_status in st.name and "views received" in vals:
                    new = {k: _int(vals, k) for k in FUSION_COUNTERS + FUSION_BUSY}
                    old = self.fusion or {}
                    if any(new[k] != old.get(k) for k in FUSION_COUNTERS):
                        self.last_change = now
                    self.fusion = new
                    self.last_diag = now

    def idle(self):
        """True while both nodes report nothing left to do."""
        return (self.depth is not None and self.fusion is not None and
                self.depth["frames received"] > 0 and
                all(self.depth[k] == 0 for k in DEPTH_BUSY) and
                all(self.fusion[k] == 0 for k in FUSION_BUSY))

    def done(self, now, image_idle, view_idle, stale):
        with self.lock:
            if self.last_frame is None or not self.idle():
                return False
            if now - self.last_frame < image_idle:
                return False
            if now - self.last_change >= view_idle:
                return True
            # The diagnostics stopped while idle (e.g. a node's timers run on
            # a /clock that stopped): nothing more will come.
            return now - self.last_diag >= stale


def main():
    rospy.init_node("finish_when_idle")
    service = rospy.get_param("~save_service", "/fusion_node/save")
    output = rospy.get_param("~output", "")
    image_idle = float(rospy.get_param("~image_idle", 3.0))
    view_idle = float(rospy.get_param("~view_idle", 4.0))
    stale = float(rospy.get_param("~stale", 20.0))
    timeout = float(rospy.get_param("~timeout", 0.0))
    f = Finisher(rospy.get_param("~depth_status", "depth_node"),
                 rospy.get_param("~fusion_status", "fusion_node"))
    rospy.Subscriber("/diagnostics", DiagnosticArray, f.on_diag, queue_size=20)
    start = time.monotonic()
    timed_out = False
    while not rospy.is_shutdown():
        time.sleep(0.5)
        now = time.monotonic()
        if f.done(now, image_idle, view_idle, stale):
            break
        if timeout > 0 and now - start > timeout:
            rospy.logerr("finish_when_idle: not idle after %.0f s: saving what "
                         "was fused", timeout)
            timed_out = True
            break
    if rospy.is_shutdown():
        return 1
    try:
        rospy.wait_for_service(service, timeout=30)
        res = rospy.ServiceProxy(service, SaveCloud)(output)
    except (rospy.ROSException, rospy.ServiceException) as e:
        rospy.logerr("finish_when_idle: %s: %s", service, e)
        return 1
    depth = f.depth or {}
    fusion = f.fusion or {}
    played = (f.last_frame - f.first_frame) if f.first_frame else 0.0
    if res.success:
        print("wild_mvs: saved %d points to %s; %d depth views; %d frames "
              "received; bag played in %.1f s; total %.1f s"
              % (res.num_points, res.message, fusion.get("views fused", 0),
                 depth.get("frames received", 0), played,
                 time.monotonic() - (f.first_frame or start)), flush=True)
        return 1 if timed_out else 0
    rospy.logerr("finish_when_idle: save failed: %s", res.message)
    return 1


if __name__ == "__main__":
    sys.exit(main())
