// Copyright wild_mvs authors.
#include "wild_mvs/ros/bus_stats.h"

#include <ros/network.h>
#include <ros/this_node.h>
#include <ros/xmlrpc_manager.h>
#include <xmlrpcpp/XmlRpcClient.h>
#include <xmlrpcpp/XmlRpcValue.h>

namespace wild_mvs {
namespace ros1 {
namespace {

bool IsArray(XmlRpc::XmlRpcValue& v) {
  return v.getType() == XmlRpc::XmlRpcValue::TypeArray;
}

int AsInt(XmlRpc::XmlRpcValue& v) {
  return v.getType() == XmlRpc::XmlRpcValue::TypeInt ? static_cast<int>(v) : 0;
}

}  // namespace

std::map<std::string, uint64_t> RoscppQueueDrops() {
  // getBusStats: [publish stats, subscribe stats, service stats]; a
  // subscription: [topic, [[connection id, bytes, messages, drops, ...]]].
  // Asked of this node's own XML-RPC server (the way rosnode and
  // rqt_graph ask; roscpp has no in-process accessor).
  std::map<std::string, uint64_t> out;
  std::string host;
  uint32_t port = 0;
  if (!ros::network::splitURI(ros::XMLRPCManager::instance()->getServerURI(),
                              host, port))
    return out;
  XmlRpc::XmlRpcClient client(host.c_str(), static_cast<int>(port), "/");
  XmlRpc::XmlRpcValue args, result;
  args[0] = ros::this_node::getName();
  if (!client.execute("getBusStats", args, result) || !IsArray(result) ||
      result.size() < 2)
    return out;
  // roscpp answers with the stats themselves; the XML-RPC API's form is
  // [code, message, stats].
  const bool wrapped =
      result.size() >= 3 && result[0].getType() == XmlRpc::XmlRpcValue::TypeInt;
  XmlRpc::XmlRpcValue& stats = wrapped ? result[2] : result;
  if (!IsArray(stats) || stats.size() < 2 || !IsArray(stats[1])) return out;
  XmlRpc::XmlRpcValue& subs = stats[1];
  for (int i = 0; i < subs.size(); ++i) {
    XmlRpc::XmlRpcValue& sub = subs[i];
    if (!IsArray(sub) || sub.size() < 2 ||
        sub[0].getType() != XmlRpc::XmlRpcValue::TypeString || !IsArray(sub[1]))
      continue;
    const std::string topic = static_cast<std::string>(sub[0]);
    uint64_t drops = 0;
    for (int c = 0; c < sub[1].size(); ++c) {
      XmlRpc::XmlRpcValue& conn = sub[1][c];
      if (IsArray(conn) && conn.size() >= 4) drops += AsInt(conn[3]);
    }
    out[topic] += drops;
  }
  return out;
}

void RoscppDropWatch::Update(
    const std::map<std::string, std::string>& topic_to_hint,
    DropCounter* drops) {
  const std::map<std::string, uint64_t> now = RoscppQueueDrops();
  for (const auto& [topic, hint] : topic_to_hint) {
    auto it = now.find(topic);
    if (it == now.end()) continue;
    uint64_t& seen = seen_[topic];
    if (it->second > seen)
      drops->CountMany(topic + ": roscpp queue full (" + hint + ")",
                       it->second - seen);
    seen = std::max(seen, it->second);
  }
}

}  // namespace ros1
}  // namespace wild_mvs
