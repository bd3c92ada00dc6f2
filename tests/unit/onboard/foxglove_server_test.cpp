// The viewer's Foxglove WebSocket server against a client written here (Boost.Beast), on
// loopback: the handshake (subprotocols, token), serverInfo and advertise, subscribe and the
// binary message frames (subscription id, stamp, CDR that reads back), latched messages for a
// late subscriber, status messages for bad requests, the built-in page over HTTP, and a client
// that stops reading: its drops are counted, the writer's calls stay fast, memory bounded.
#include "semap/onboard/foxglove_server.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <chrono>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <thread>
#include <variant>

#include "semap/dds_idl/message_tap.hpp"
#include "semap/dds_idl/types.hpp"

namespace semap::onboard {
namespace {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
using tcp = asio::ip::tcp;
using json = nlohmann::json;
using namespace std::chrono_literals;

FoxgloveServer::Options options(std::string token = "", std::size_t budget = 8u << 20) {
  FoxgloveServer::Options o;
  o.port = 0;
  o.token = std::move(token);
  o.client_budget_bytes = budget;
  o.files = {{"index.html", "<html>semap viewer</html>"}, {"app.js", "let x = 1;"}};
  return o;
}

std::vector<std::uint8_t> odometry_cdr(double x) {
  dds_idl::msg::Odometry m{};
  m.header_.frame_id_ = const_cast<char*>("map");
  m.child_frame_id_ = const_cast<char*>("base_link");
  m.pose_.pose_.position_.x_ = x;
  m.pose_.pose_.orientation_.w_ = 1.0;
  std::vector<std::uint8_t> out;
  dds_idl::serialize_cdr(m, out);
  return out;
}

double odometry_x(std::span<const std::uint8_t> cdr) {
  dds_idl::msg::Odometry m{};
  EXPECT_TRUE(dds_idl::deserialize_cdr(cdr, m));
  const double x = m.pose_.pose_.position_.x_;
  dds_sample_free(&m, dds_idl::TypeDescriptor<dds_idl::msg::Odometry>::get(), DDS_FREE_CONTENTS);
  return x;
}

struct Frame {
  std::uint32_t subscription = 0;
  std::uint64_t stamp_ns = 0;
  std::vector<std::uint8_t> payload;
};

// A synchronous client with a deadline on every read.
class Client {
 public:
  // Throws beast::system_error when the server refuses the handshake.
  Client(std::uint16_t port, const std::string& target = "/",
         std::string subprotocols = "foxglove.websocket.v1")
      : ws_(io_) {
    tcp::resolver resolver(io_);
    beast::get_lowest_layer(ws_).connect(
        *resolver.resolve("127.0.0.1", std::to_string(port)).begin());
    ws_.set_option(websocket::stream_base::decorator([subprotocols](websocket::request_type& r) {
      r.set(http::field::sec_websocket_protocol, subprotocols);
    }));
    websocket::response_type response;
    ws_.handshake(response, "127.0.0.1", target);
    subprotocol_ = std::string(response[http::field::sec_websocket_protocol]);
  }

  const std::string& subprotocol() const { return subprotocol_; }

  // The next message: text as JSON, or a binary frame.
  std::variant<json, Frame> next(std::chrono::milliseconds timeout = 5000ms) {
    beast::flat_buffer buffer;
    beast::get_lowest_layer(ws_).expires_after(timeout);
    ws_.read(buffer);
    const auto data = static_cast<const std::uint8_t*>(buffer.data().data());
    if (ws_.got_text()) return json::parse(beast::buffers_to_string(buffer.data()));
    EXPECT_GE(buffer.size(), 13u);
    EXPECT_EQ(data[0], 0x01);
    Frame f;
    for (int i = 0; i < 4; ++i) f.subscription |= std::uint32_t{data[1 + i]} << (8 * i);
    for (int i = 0; i < 8; ++i) f.stamp_ns |= std::uint64_t{data[5 + i]} << (8 * i);
    f.payload.assign(data + 13, data + buffer.size());
    return f;
  }
  json next_json(const std::string& op) {
    for (int i = 0; i < 100; ++i) {
      auto m = next();
      if (auto* j = std::get_if<json>(&m); j && (*j)["op"] == op) return *j;
    }
    ADD_FAILURE() << "no " << op;
    return {};
  }
  Frame next_frame() {
    for (int i = 0; i < 100; ++i) {
      auto m = next();
      if (auto* f = std::get_if<Frame>(&m)) return *f;
    }
    ADD_FAILURE() << "no message frame";
    return {};
  }
  void send(const json& j) {
    ws_.text(true);
    ws_.write(asio::buffer(j.dump()));
  }
  websocket::stream<beast::tcp_stream>& ws() { return ws_; }

 private:
  asio::io_context io_;
  websocket::stream<beast::tcp_stream> ws_;
  std::string subprotocol_;
};

std::optional<std::uint32_t> channel_id(const json& advertise, const std::string& topic) {
  for (const auto& c : advertise["channels"]) {
    if (c["topic"] == topic) return c["id"].get<std::uint32_t>();
  }
  return std::nullopt;
}

// HTTP GET; returns status and body.
std::pair<int, std::string> get(std::uint16_t port, const std::string& target) {
  asio::io_context io;
  beast::tcp_stream stream(io);
  tcp::resolver resolver(io);
  stream.connect(*resolver.resolve("127.0.0.1", std::to_string(port)).begin());
  http::request<http::empty_body> req(http::verb::get, target, 11);
  req.set(http::field::host, "127.0.0.1");
  http::write(stream, req);
  beast::flat_buffer buffer;
  http::response<http::string_body> res;
  stream.expires_after(5s);
  http::read(stream, buffer, res);
  return {static_cast<int>(res.result_int()), res.body()};
}

template <typename F>
bool eventually(F&& f, std::chrono::milliseconds timeout = 5000ms) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < deadline) {
    if (f()) return true;
    std::this_thread::sleep_for(10ms);
  }
  return f();
}

TEST(FoxgloveServer, ServerInfoAdvertiseSubscribeAndMessageFrames) {
  FoxgloveServer server(options());
  const auto odom =
      server.add_channel({"/semap/odometry", "nav_msgs/msg/Odometry", /*latched=*/false});
  server.add_channel({"/semap/costmap", "nav_msgs/msg/OccupancyGrid", true});
  server.start();
  ASSERT_NE(server.port(), 0);
  EXPECT_EQ(server.url(), "http://127.0.0.1:" + std::to_string(server.port()) + "/");

  Client client(server.port());
  EXPECT_EQ(client.subprotocol(), "foxglove.websocket.v1");
  const json info = client.next_json("serverInfo");
  EXPECT_EQ(info["name"], "semap-onboard");
  EXPECT_TRUE(info["capabilities"].is_array());
  EXPECT_TRUE(info.contains("sessionId"));
  const json advertise = client.next_json("advertise");
  ASSERT_EQ(advertise["channels"].size(), 2u);
  const json& c = advertise["channels"][0];
  EXPECT_EQ(c["topic"], "/semap/odometry");
  EXPECT_EQ(c["encoding"], "cdr");
  EXPECT_EQ(c["schemaName"], "nav_msgs/msg/Odometry");
  EXPECT_EQ(c["schemaEncoding"], "ros2msg");
  EXPECT_NE(c["schema"].get<std::string>().find("MSG: geometry_msgs/Pose"), std::string::npos);
  ASSERT_EQ(channel_id(advertise, "/semap/odometry"), odom);

  client.send({{"op", "subscribe"}, {"subscriptions", {{{"id", 42}, {"channelId", odom}}}}});
  ASSERT_TRUE(eventually([&] { return server.subscribed(odom); }));
  const auto stamp = common::Stamp::now();
  server.on_message(odom, stamp, odometry_cdr(7.25));
  const Frame f = client.next_frame();
  EXPECT_EQ(f.subscription, 42u);
  EXPECT_EQ(odometry_x(f.payload), 7.25);
  // The stamp is the system clock's (what Foxglove's timeline shows), within a second of now.
  const auto now_ns = std::chrono::duration_cast<std::chrono::nanoseconds>(
                          std::chrono::system_clock::now().time_since_epoch())
                          .count();
  EXPECT_LT(std::abs(static_cast<double>(f.stamp_ns) - static_cast<double>(now_ns)), 1e9);

  // Counted once the server's write completes, which may be just after the client has it.
  ASSERT_TRUE(eventually([&] {
    const auto clients = server.clients();
    return clients.size() == 1 && clients[0].messages_sent >= 1;
  }));
  EXPECT_GT(server.clients()[0].bytes_sent, f.payload.size());

  // Unsubscribed: no more frames; the server keeps serving.
  client.send({{"op", "unsubscribe"}, {"subscriptionIds", {42}}});
  ASSERT_TRUE(eventually([&] { return !server.subscribed(odom); }));
}

TEST(FoxgloveServer, AnswersTheSdkSubprotocolAndRefusesOthers) {
  FoxgloveServer server(options());
  server.start();
  Client sdk(server.port(), "/", "foxglove.sdk.v1");
  EXPECT_EQ(sdk.subprotocol(), "foxglove.sdk.v1");
  Client both(server.port(), "/", "foxglove.sdk.v1, foxglove.websocket.v1");
  EXPECT_EQ(both.subprotocol(), "foxglove.sdk.v1");
  EXPECT_THROW(Client(server.port(), "/", "graphql-ws"), beast::system_error);
  EXPECT_GE(server.counters().clients_refused, 1u);
}

TEST(FoxgloveServer, TokenIsRequiredOnWebSocketAndHttp) {
  FoxgloveServer server(options("s3cret"));
  server.start();
  EXPECT_THROW(Client(server.port(), "/"), beast::system_error);
  EXPECT_THROW(Client(server.port(), "/?token=wrong"), beast::system_error);
  Client ok(server.port(), "/?token=s3cret");
  EXPECT_EQ(ok.next_json("serverInfo")["op"], "serverInfo");
  EXPECT_EQ(get(server.port(), "/").first, 401);
  EXPECT_EQ(get(server.port(), "/?token=s3cret").first, 200);
  EXPECT_EQ(server.counters().clients_refused, 2u);
}

TEST(FoxgloveServer, ServesThePageOverHttp) {
  FoxgloveServer server(options());
  server.start();
  EXPECT_EQ(get(server.port(), "/"), std::make_pair(200, std::string("<html>semap viewer</html>")));
  EXPECT_EQ(get(server.port(), "/app.js").second, "let x = 1;");
  EXPECT_EQ(get(server.port(), "/missing.js").first, 404);
}

TEST(FoxgloveServer, LateSubscriberGetsTheLatchedMessageAtOnce) {
  FoxgloveServer server(options());
  const auto latched = server.add_channel({"/semap/tf_static", "tf2_msgs/msg/TFMessage", true});
  const auto odom = server.add_channel({"/semap/odometry", "nav_msgs/msg/Odometry", false});
  server.start();
  server.on_message(latched, common::Stamp::now(), odometry_cdr(1.0));
  server.on_message(latched, common::Stamp::now(), odometry_cdr(2.0));  // the newest
  server.on_message(odom, common::Stamp::now(), odometry_cdr(3.0));     // nobody listens: gone
  std::this_thread::sleep_for(100ms);
  Client client(server.port());
  client.next_json("advertise");
  client.send(
      {{"op", "subscribe"},
       {"subscriptions", {{{"id", 1}, {"channelId", latched}}, {{"id", 2}, {"channelId", odom}}}}});
  const Frame f = client.next_frame();
  EXPECT_EQ(f.subscription, 1u);
  EXPECT_EQ(odometry_x(f.payload), 2.0);
}

TEST(FoxgloveServer, BadRequestsGetAStatusAndTheClientStays) {
  FoxgloveServer server(options());
  const auto odom = server.add_channel({"/semap/odometry", "nav_msgs/msg/Odometry", false});
  server.start();
  Client client(server.port());
  client.next_json("advertise");
  client.send({{"op", "subscribe"}, {"subscriptions", {{{"id", 1}, {"channelId", 99}}}}});
  json status = client.next_json("status");
  EXPECT_EQ(status["level"], 2);
  EXPECT_NE(status["message"].get<std::string>().find("unknown channel id 99"), std::string::npos);
  client.send({{"op", "subscribe"}, {"subscriptions", {{{"id", 1}, {"channelId", odom}}}}});
  client.send({{"op", "subscribe"}, {"subscriptions", {{{"id", 1}, {"channelId", odom}}}}});
  status = client.next_json("status");
  EXPECT_NE(status["message"].get<std::string>().find("in use"), std::string::npos);
  client.ws().text(true);
  client.ws().write(asio::buffer(std::string("{not json")));
  EXPECT_EQ(client.next_json("status")["level"], 2);
  client.send({{"op", "getParameters"}, {"parameterNames", json::array()}});
  EXPECT_NE(client.next_json("status")["message"].get<std::string>().find("unsupported op"),
            std::string::npos);
  // Still subscribed and served.
  server.on_message(odom, common::Stamp::now(), odometry_cdr(5.0));
  EXPECT_EQ(odometry_x(client.next_frame().payload), 5.0);
  EXPECT_EQ(server.counters().clients_closed_error, 0u);
}

std::size_t rss_bytes() {
  std::ifstream statm("/proc/self/statm");
  std::size_t pages = 0, resident = 0;
  statm >> pages >> resident;
  return resident * static_cast<std::size_t>(sysconf(_SC_PAGESIZE));
}

TEST(FoxgloveServer, StalledClientLosesDroppableMessagesNotTheWritersTime) {
  constexpr std::size_t kBudget = 1u << 20;
  FoxgloveServer server(options("", kBudget));
  const auto images = server.add_channel(
      {"/semap/camera/image/compressed", "sensor_msgs/msg/CompressedImage", false});
  const auto map = server.add_channel({"/semap/map_cloud", "sensor_msgs/msg/PointCloud2", true});
  server.start();
  Client stalled(server.port());
  stalled.next_json("advertise");
  stalled.send(
      {{"op", "subscribe"},
       {"subscriptions", {{{"id", 1}, {"channelId", images}}, {{"id", 2}, {"channelId", map}}}}});
  ASSERT_TRUE(eventually([&] { return server.subscribed(images) && server.subscribed(map); }));
  // From here on the client reads nothing: its socket and the server's queue fill.
  const std::vector<std::uint8_t> big(512 * 1024, 0x5a);
  [[maybe_unused]] const std::size_t rss_before = rss_bytes();
  double slowest_ms = 0.0;
  constexpr int kMessages = 400;  // 200 MB offered
  for (int i = 0; i < kMessages; ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    server.on_message(i % 10 == 0 ? map : images, common::Stamp::now(), big);
    slowest_ms = std::max(
        slowest_ms,
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    std::this_thread::sleep_for(1ms);
  }
  ASSERT_TRUE(eventually([&] {
    const auto c = server.clients();
    return c.size() == 1 && c[0].messages_dropped > 0;
  }));
  std::this_thread::sleep_for(200ms);
  const auto c = server.clients().at(0);
  // The writer only copied and queued (a 512 KiB copy): never waited for the client.
  EXPECT_LT(slowest_ms, 50.0);
  // Most images were dropped for it; what was sent fits the budget plus the socket buffers.
  EXPECT_GT(c.messages_dropped, kMessages / 2);
  EXPECT_LT(c.messages_sent + c.messages_dropped, static_cast<std::uint64_t>(kMessages) + 1);
#if !defined(__SANITIZE_ADDRESS__)
  // (Under ASan freed copies wait in its quarantine, up to 256 MB: RSS then says nothing.)
  const std::size_t grown = rss_bytes() > rss_before ? rss_bytes() - rss_before : 0;
  EXPECT_LT(grown, 64u << 20) << "the server holds what a stalled client does not read";
#endif
  EXPECT_EQ(server.counters().messages_dropped, c.messages_dropped);

  // A second, healthy client is served meanwhile.
  Client healthy(server.port());
  healthy.next_json("advertise");
  healthy.send({{"op", "subscribe"}, {"subscriptions", {{{"id", 9}, {"channelId", images}}}}});
  ASSERT_TRUE(eventually([&] { return server.clients().size() == 2; }));
  std::this_thread::sleep_for(100ms);
  server.on_message(images, common::Stamp::now(), big);
  EXPECT_EQ(healthy.next_frame().subscription, 9u);
  server.stop();  // does not hang on the stalled client
}

}  // namespace
}  // namespace semap::onboard
