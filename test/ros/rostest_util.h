// Copyright wild_mvs authors. Helpers of the rostest checker nodes.
#pragma once

#include <diagnostic_msgs/DiagnosticArray.h>
#include <gtest/gtest.h>
#include <ros/network.h>
#include <ros/ros.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/PointCloud2.h>
#include <sensor_msgs/point_cloud2_iterator.h>
#include <std_srvs/SetBool.h>
#include <unistd.h>
#include <xmlrpcpp/XmlRpcClient.h>

#include <cstdlib>
#include <fstream>
#include <map>
#include <mutex>
#include <set>
#include <string>
#include <thread>

#include "wild_mvs/core/point_cloud.h"

namespace wild_mvs {
namespace testing {

// The fixture of a rostest whose cases check what one scenario produced:
// `Run` (with Run(), `complete` and `failure`) is run once before the first
// case and deleted after the last; every case fails at once, with the
// reason, when the run did not complete. Base: ::testing::Test, or
// ::testing::TestWithParam<T> for cases per parameter.
template <typename Run, typename Base = ::testing::Test>
class RunOnce : public Base {
 protected:
  static void SetUpTestSuite() {
    run_ = new Run();
    run_->Run();
  }
  static void TearDownTestSuite() {
    delete run_;
    run_ = nullptr;
  }
  void SetUp() override { ASSERT_TRUE(run_->complete) << run_->failure; }
  static Run* run_;
};
template <typename Run, typename Base>
Run* RunOnce<Run, Base>::run_ = nullptr;

// Latest diagnostics values per status name ("depth_node: depth_node").
class DiagnosticsWatch {
 public:
  explicit DiagnosticsWatch(ros::NodeHandle& nh) {
    sub_ = nh.subscribe("/diagnostics", 50, &DiagnosticsWatch::On, this);
  }
  // Values of the newest status whose name contains `name_part`.
  std::map<std::string, std::string> Values(const std::string& name_part) {
    std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& [name, vals] : latest_)
      if (name.find(name_part) != std::string::npos) return vals;
    return {};
  }
  long Get(const std::string& name_part, const std::string& key) {
    auto v = Values(name_part);
    auto it = v.find(key);
    return it == v.end() ? -1 : std::atol(it->second.c_str());
  }
  // Sum of the "dropped: ..." entries of `name_part` whose key contains
  // `reason_part`.
  long Dropped(const std::string& name_part, const std::string& reason_part) {
    long n = 0;
    for (const auto& [k, v] : Values(name_part))
      if (k.rfind("dropped: ", 0) == 0 &&
          k.find(reason_part) != std::string::npos)
        n += std::atol(v.c_str());
    return n;
  }
  std::string Dump(const std::string& name_part) {
    std::string s;
    for (const auto& [k, v] : Values(name_part))
      s += "  " + k + " = " + v + "\n";
    return s;
  }

 private:
  void On(const diagnostic_msgs::DiagnosticArrayConstPtr& msg) {
    std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& st : msg->status) {
      auto& m = latest_[st.name];
      m.clear();
      for (const auto& kv : st.values) m[kv.key] = kv.value;
    }
  }
  std::mutex mutex_;
  std::map<std::string, std::map<std::string, std::string>> latest_;
  ros::Subscriber sub_;
};

// Waits (spinning in the background) until pred() or the timeout.
template <typename Pred>
bool WaitFor(Pred pred, double seconds) {
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(seconds);
  while (ros::ok() && ros::WallTime::now() < end) {
    if (pred()) return true;
    ros::WallDuration(0.1).sleep();
  }
  return pred();
}

inline PointCloud CloudFromMsg(const sensor_msgs::PointCloud2& msg) {
  PointCloud c;
  if (msg.width * msg.height == 0) return c;
  sensor_msgs::PointCloud2ConstIterator<float> x(msg, "x"), y(msg, "y"),
      z(msg, "z");
  for (; x != x.end(); ++x, ++y, ++z) c.xyz.emplace_back(*x, *y, *z);
  return c;
}

// Calls the slave API method `method` of `node` (looked up at the master)
// with this node as caller; false when the node or the call fails. `result`
// is the call's [code, message, value].
inline bool CallNodeApi(const std::string& node, const std::string& method,
                        XmlRpc::XmlRpcValue* result) {
  XmlRpc::XmlRpcValue args, lookup, payload;
  args[0] = ros::this_node::getName();
  args[1] = node;
  if (!ros::master::execute("lookupNode", args, lookup, payload, false))
    return false;
  std::string uri = payload;
  std::string host;
  uint32_t port = 0;
  if (!ros::network::splitURI(uri, host, port)) return false;
  XmlRpc::XmlRpcClient client(host.c_str(), port, "/");
  XmlRpc::XmlRpcValue a;
  a[0] = ros::this_node::getName();
  return client.execute(method.c_str(), a, *result) &&
         result->getType() == XmlRpc::XmlRpcValue::TypeArray &&
         result->size() >= 3;
}

// Process id of a node (XML-RPC getPid), or -1.
inline int NodePid(const std::string& node) {
  XmlRpc::XmlRpcValue r;
  if (!CallNodeApi(node, "getPid", &r)) return -1;
  return static_cast<int>(r[2]);
}

// Connected subscribers per topic that `node` publishes (its getBusInfo:
// [id, destination, direction "o"/"i", transport, topic, connected, ...]).
inline std::map<std::string, int> PublishedConnections(
    const std::string& node) {
  std::map<std::string, int> out;
  XmlRpc::XmlRpcValue r;
  if (!CallNodeApi(node, "getBusInfo", &r) ||
      r[2].getType() != XmlRpc::XmlRpcValue::TypeArray)
    return out;
  for (int i = 0; i < r[2].size(); ++i) {
    XmlRpc::XmlRpcValue& c = r[2][i];
    if (c.getType() != XmlRpc::XmlRpcValue::TypeArray || c.size() < 5 ||
        c[2].getType() != XmlRpc::XmlRpcValue::TypeString ||
        c[4].getType() != XmlRpc::XmlRpcValue::TypeString)
      continue;
    if (static_cast<std::string>(c[2]) != "o") continue;
    if (c.size() >= 6 && c[5].getType() == XmlRpc::XmlRpcValue::TypeBoolean &&
        !static_cast<bool>(c[5]))
      continue;
    ++out[static_cast<std::string>(c[4])];
  }
  return out;
}

// Peak resident set size (VmHWM) of a process in MB, or -1.
inline double PeakRssMb(int pid) {
  std::ifstream f("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(f, line))
    if (line.rfind("VmHWM:", 0) == 0)
      return std::atof(line.c_str() + 6) / 1024.0;
  return -1;
}

// The vertex count of the PLY file at `path` (its header), or -1 when the
// file is missing or does not start with "ply".
inline long PlyVertexCount(const std::string& path) {
  std::ifstream ply(path, std::ios::binary);
  std::string line;
  if (!std::getline(ply, line) || line != "ply") return -1;
  long vertices = -1;
  while (std::getline(ply, line) && line != "end_header")
    if (line.rfind("element vertex ", 0) == 0)
      vertices = std::stol(line.substr(15));
  return vertices;
}

// Runs `rosbag play` on `bag` in a background thread.
inline std::thread PlayBag(const std::string& bag, double rate,
                           const std::string& extra = "") {
  // `extra` after the bag: --topics takes every argument that follows it.
  // -d: a pause after each advertise so that every subscriber (image AND
  // camera_info, which are paired by exact stamp) is connected before the
  // first message, as reconstruct_bag.launch does.
  const std::string cmd = "rosbag play --quiet -d 0.3 -r " +
                          std::to_string(rate) + " '" + bag + "' " + extra +
                          " >/dev/null 2>&1";
  return std::thread([cmd] {
    if (std::system(cmd.c_str()) != 0) ROS_ERROR("failed: %s", cmd.c_str());
  });
}

// Runs `rosbag play` on `bag` in a background thread, started paused and
// unpaused only once every topic of the bag has at least `min_subscribers`
// connected subscribers at the player (its outgoing connections), so that
// no subscriber misses the first messages however slowly its connections
// come up on a loaded machine (a fixed -d pause was not enough: a nodelet
// manager connected after the first image). Fails the test (ADD_FAILURE)
// when the connections do not come within `timeout` seconds; plays anyway.
inline std::thread PlayBagConnected(const std::string& bag, double rate,
                                    int min_subscribers,
                                    const std::string& extra = "",
                                    double timeout = 60.0) {
  const std::string name =
      "wild_mvs_player_" + std::to_string(getpid()) + "_" +
      std::to_string(ros::WallTime::now().toNSec() % 1000000000ull);
  std::set<std::string> topics;
  {
    rosbag::Bag b(bag, rosbag::bagmode::Read);
    rosbag::View view(b);
    for (const rosbag::ConnectionInfo* c : view.getConnections())
      topics.insert(c->topic);
  }
  const std::string cmd = "rosbag play --quiet --pause -r " +
                          std::to_string(rate) + " '" + bag + "' " + extra +
                          " __name:=" + name + " >/dev/null 2>&1";
  return std::thread([cmd, name, topics, min_subscribers, timeout] {
    std::thread play([cmd] {
      if (std::system(cmd.c_str()) != 0) ROS_ERROR("failed: %s", cmd.c_str());
    });
    const std::string node = "/" + name;
    std::map<std::string, int> connected;
    const bool ready = WaitFor(
        [&] {
          connected = PublishedConnections(node);
          for (const std::string& t : topics)
            if (connected[t] < min_subscribers) return false;
          return ros::service::exists(node + "/pause_playback", false);
        },
        timeout);
    if (!ready) {
      std::string s;
      for (const std::string& t : topics)
        s += " " + t + ":" + std::to_string(connected[t]);
      ADD_FAILURE() << "rosbag play " << node << ": fewer than "
                    << min_subscribers << " subscribers after " << timeout
                    << " s:" << s;
    }
    std_srvs::SetBool resume;
    resume.request.data = false;
    if (!WaitFor(
            [&] {
              return ros::service::call(node + "/pause_playback", resume);
            },
            10))
      ADD_FAILURE() << "could not unpause " << node;
    play.join();
  });
}

}  // namespace testing
}  // namespace wild_mvs
