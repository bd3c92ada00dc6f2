// One Foxglove WebSocket client session of FoxgloveServer (foxglove_server_impl.hpp): the
// handshake, the client's text ops (subscribe, unsubscribe), its queue with the byte budget
// (drops, latched coalescing) and the writes.
#include <exception>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "foxglove_server_impl.hpp"
#include "semap/common/logging.hpp"

namespace semap::onboard {

namespace {

void put_le(std::string& out, std::uint64_t v, int bytes) {
  for (int i = 0; i < bytes; ++i) out.push_back(static_cast<char>((v >> (8 * i)) & 0xffu));
}

}  // namespace

FoxgloveServer::Impl::Client::Client(Impl& server, beast::tcp_stream&& stream, std::string address)
    : server_(server),
      ws_(std::move(stream)),
      address_(std::move(address)),
      connected_(common::Stamp::now()) {}

void FoxgloveServer::Impl::Client::accept(http::request<http::string_body> request,
                                          std::string subprotocol) {
  ws_.set_option(websocket::stream_base::timeout::suggested(beast::role_type::server));
  ws_.set_option(websocket::stream_base::decorator([subprotocol](websocket::response_type& r) {
    r.set(http::field::sec_websocket_protocol, subprotocol);
    r.set(http::field::server, "semap-onboard");
  }));
  ws_.read_message_max(1u << 20);
  ws_.async_accept(request, [self = shared_from_this()](beast::error_code ec) {
    if (ec) return self->fail(ec, "accept");
    self->on_open();
  });
}

void FoxgloveServer::Impl::Client::deliver(const MessagePtr& m, bool latched) {
  const auto sub = by_channel_.find(m->channel);
  if (sub == by_channel_.end()) return;
  if (queued_bytes_ > server_.options_.client_budget_bytes) {
    if (latched) {
      pending_latched_[m->channel] = m;  // coalesced to the newest
    } else {
      dropped_.fetch_add(1, std::memory_order_relaxed);
    }
    return;
  }
  send_data(sub->second, *m);
}

void FoxgloveServer::Impl::Client::send_text(const json& j) {
  enqueue(std::make_shared<std::string>(j.dump()), false);
}

void FoxgloveServer::Impl::Client::close() {
  if (closing_) return;
  closing_ = true;
  ws_.async_close(websocket::close_code::going_away,
                  [self = shared_from_this()](beast::error_code) {});
}

dds_idl::ViewerClientData FoxgloveServer::Impl::Client::figures() const {
  return {address_, bytes_.load(std::memory_order_relaxed),
          messages_.load(std::memory_order_relaxed), dropped_.load(std::memory_order_relaxed),
          static_cast<float>(common::seconds_between(common::Stamp::now(), connected_))};
}

void FoxgloveServer::Impl::Client::on_open() {
  open_ = true;
  json info = {{"op", "serverInfo"},
               {"name", server_.options_.name},
               {"capabilities", json::array()},
               {"sessionId", server_.session_id_}};
  json metadata = json::object();
  for (const auto& [k, v] : server_.options_.metadata) metadata[k] = v;
  info["metadata"] = metadata;
  send_text(info);
  std::vector<std::uint32_t> ids;
  {
    std::lock_guard lock(server_.channels_mutex_);
    for (std::uint32_t i = 0; i < server_.channels_.size(); ++i) ids.push_back(i);
  }
  send_text(server_.advertise(ids));
  read();
}

void FoxgloveServer::Impl::Client::read() {
  ws_.async_read(in_, [self = shared_from_this()](beast::error_code ec, std::size_t) {
    if (ec) return self->fail(ec, "read");
    try {
      if (self->ws_.got_text()) {
        self->on_text(beast::buffers_to_string(self->in_.data()));
      } else {
        self->status(2, "binary client messages are not supported (no clientPublish)");
      }
    } catch (const std::exception& e) {
      ++self->server_.bad_requests_;
      self->status(2, std::string("bad request: ") + e.what());
    }
    self->in_.consume(self->in_.size());
    self->read();
  });
}

void FoxgloveServer::Impl::Client::status(int level, const std::string& message) {
  if (level > 0) ++server_.bad_requests_;
  send_text({{"op", "status"}, {"level", level}, {"message", message}});
}

void FoxgloveServer::Impl::Client::on_text(const std::string& text) {
  const json j = json::parse(text);
  const std::string op = j.at("op").get<std::string>();
  if (op == "subscribe") {
    for (const auto& s : j.at("subscriptions")) {
      const auto id = s.at("id").get<std::uint32_t>();
      const auto channel = s.at("channelId").get<std::uint32_t>();
      const auto ch = server_.channel(channel);
      if (!ch) {
        status(2, "subscribe: unknown channel id " + std::to_string(channel));
        continue;
      }
      if (subscriptions_.count(id) != 0) {
        status(2, "subscribe: subscription id " + std::to_string(id) + " is in use");
        continue;
      }
      if (by_channel_.count(channel) != 0) {
        status(2, "subscribe: channel " + std::to_string(channel) + " is already subscribed");
        continue;
      }
      subscriptions_[id] = channel;
      by_channel_[channel] = id;
      server_.subscribers_[channel].fetch_add(1);
      // A late joiner gets the latched channel's newest message at once.
      const auto latest = server_.latest_.find(channel);
      if (latest != server_.latest_.end()) deliver(latest->second, true);
    }
  } else if (op == "unsubscribe") {
    for (const auto& s : j.at("subscriptionIds")) {
      const auto id = s.get<std::uint32_t>();
      const auto it = subscriptions_.find(id);
      if (it == subscriptions_.end()) {
        status(1, "unsubscribe: unknown subscription id " + std::to_string(id));
        continue;
      }
      server_.subscribers_[it->second].fetch_sub(1);
      pending_latched_.erase(it->second);
      by_channel_.erase(it->second);
      subscriptions_.erase(it);
    }
  } else {
    status(2, "unsupported op \"" + op + "\"");
  }
}

void FoxgloveServer::Impl::Client::release_subscriptions() {
  for (const auto& [id, channel] : subscriptions_) server_.subscribers_[channel].fetch_sub(1);
  subscriptions_.clear();
  by_channel_.clear();
  pending_latched_.clear();
}

void FoxgloveServer::Impl::Client::send_data(std::uint32_t subscription, const Message& m) {
  auto frame = std::make_shared<std::string>();
  frame->reserve(13 + m.cdr.size());
  frame->push_back(static_cast<char>(0x01));
  put_le(*frame, subscription, 4);
  put_le(*frame, m.stamp_ns, 8);
  frame->append(reinterpret_cast<const char*>(m.cdr.data()), m.cdr.size());
  enqueue(std::move(frame), true);
}

void FoxgloveServer::Impl::Client::enqueue(std::shared_ptr<std::string> frame, bool binary) {
  if (closing_) return;
  queued_bytes_ += frame->size();
  queue_.push_back({std::move(frame), binary});
  if (!writing_ && open_) write();
}

void FoxgloveServer::Impl::Client::write() {
  if (queue_.empty()) {
    writing_ = false;
    return;
  }
  writing_ = true;
  const Out& out = queue_.front();
  ws_.binary(out.binary);
  ws_.async_write(asio::buffer(*out.frame),
                  [self = shared_from_this()](beast::error_code ec, std::size_t n) {
                    if (ec) return self->fail(ec, "write");
                    self->on_written(n);
                  });
}

void FoxgloveServer::Impl::Client::on_written(std::size_t n) {
  const Out out = std::move(queue_.front());
  queue_.pop_front();
  queued_bytes_ -= out.frame->size();
  bytes_.fetch_add(n, std::memory_order_relaxed);
  if (out.binary) messages_.fetch_add(1, std::memory_order_relaxed);
  // Caught up: what the latched channels hold now goes out.
  if (queued_bytes_ <= server_.options_.client_budget_bytes && !pending_latched_.empty()) {
    auto pending = std::move(pending_latched_);
    pending_latched_.clear();
    for (const auto& [channel, m] : pending) {
      const auto sub = by_channel_.find(channel);
      if (sub != by_channel_.end()) send_data(sub->second, *m);
    }
  }
  write();
}

void FoxgloveServer::Impl::Client::fail(beast::error_code ec, const char* what) {
  if (failed_) return;
  failed_ = true;
  // A client that went away (closed, or its process ended: reset, end of stream) is a
  // normal end; anything else (a protocol error, a timeout) closed it on an error.
  const bool normal = ec == websocket::error::closed || ec == asio::error::operation_aborted ||
                      ec == asio::error::eof || ec == asio::error::connection_reset ||
                      ec == asio::error::broken_pipe || ec == http::error::end_of_stream ||
                      closing_;
  if (!normal) {
    common::logger("viewer")->info("viewer: client {} closed: {} ({})", address_, ec.message(),
                                   what);
  }
  server_.remove(shared_from_this(), !normal);
}

}  // namespace semap::onboard
