#include "semap/map_io/pcd_io.hpp"

#include <charconv>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <sstream>
#include <vector>

#include "semap/common/logging.hpp"

namespace semap::map_io {

namespace {

// Generous bounds that keep a hostile header from asking for absurd allocations.
constexpr std::size_t kMaxCount = 4096;
constexpr std::size_t kMaxFields = 256;

struct Field {
  std::string name;
  std::size_t size = 4;
  char type = 'F';
  std::size_t count = 1;
  std::size_t offset = 0;  // first value index (ascii) or byte offset (binary)
};

struct Header {
  std::vector<Field> fields;
  std::size_t width = 0;
  std::size_t height = 1;
  std::size_t points = 0;
  bool has_points = false;
  Eigen::Vector3f viewpoint = Eigen::Vector3f::Zero();
  std::string data;
  std::size_t data_line = 0;   // line number of the DATA line
  std::size_t data_start = 0;  // byte offset after the DATA line
};

class Parser {
 public:
  Parser(std::string_view bytes, const std::string& name) : bytes_(bytes), name_(name) {}

  PcdScan parse();

 private:
  [[noreturn]] void fail(std::size_t line, const std::string& what) const {
    throw PcdError(name_ + ":" + std::to_string(line) + ": " + what);
  }
  [[noreturn]] void fail(const std::string& what) const { throw PcdError(name_ + ": " + what); }

  Header read_header();
  void read_ascii(const Header& h, PcdScan& scan);
  void read_binary(const Header& h, PcdScan& scan);
  void prepare(const Header& h, PcdScan& scan);

  std::string_view bytes_;
  std::string name_;
  // Index of the x, y, z, label, prob fields in Header::fields, or -1.
  int x_ = -1, y_ = -1, z_ = -1, label_ = -1, prob_ = -1;
};

std::vector<std::string_view> split(std::string_view line) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
    const std::size_t start = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t' && line[i] != '\r') ++i;
    if (i > start) out.push_back(line.substr(start, i - start));
  }
  return out;
}

bool parse_size(std::string_view s, std::size_t& out) {
  const auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), out);
  return ec == std::errc() && p == s.data() + s.size();
}

bool parse_double(std::string_view s, double& out) {
  const auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), out);
  return ec == std::errc() && p == s.data() + s.size();
}

// Reads the next line starting at `pos`; returns false at the end of the bytes.
bool next_line(std::string_view bytes, std::size_t& pos, std::string_view& line) {
  if (pos >= bytes.size()) return false;
  const std::size_t end = bytes.find('\n', pos);
  const std::size_t stop = end == std::string_view::npos ? bytes.size() : end;
  line = bytes.substr(pos, stop - pos);
  pos = stop == bytes.size() ? stop : stop + 1;
  return true;
}

Header Parser::read_header() {
  Header h;
  std::size_t pos = 0;
  std::size_t line_no = 0;
  std::string_view line;
  bool have_sizes = false, have_types = false, have_counts = false;
  while (next_line(bytes_, pos, line)) {
    ++line_no;
    const auto tokens = split(line);
    if (tokens.empty() || tokens[0].front() == '#') continue;
    const std::string_view key = tokens[0];
    const std::size_t n = tokens.size() - 1;
    if (key == "VERSION") continue;
    if (key == "FIELDS") {
      if (n == 0 || n > kMaxFields) fail(line_no, "FIELDS needs 1.." + std::to_string(kMaxFields));
      h.fields.resize(n);
      for (std::size_t i = 0; i < n; ++i) h.fields[i].name = std::string(tokens[i + 1]);
    } else if (key == "SIZE" || key == "TYPE" || key == "COUNT") {
      if (h.fields.empty()) fail(line_no, std::string(key) + " before FIELDS");
      if (n != h.fields.size()) {
        fail(line_no, std::string(key) + " has " + std::to_string(n) + " entries for " +
                          std::to_string(h.fields.size()) + " fields");
      }
      for (std::size_t i = 0; i < n; ++i) {
        const std::string_view t = tokens[i + 1];
        Field& f = h.fields[i];
        if (key == "TYPE") {
          if (t.size() != 1 || (t[0] != 'F' && t[0] != 'U' && t[0] != 'I')) {
            fail(line_no, "TYPE of field " + f.name + " must be F, U or I");
          }
          f.type = t[0];
        } else {
          std::size_t v = 0;
          if (!parse_size(t, v) || v == 0 || v > kMaxCount) {
            fail(line_no, std::string(key) + " of field " + f.name + " is invalid");
          }
          (key == "SIZE" ? f.size : f.count) = v;
        }
      }
      (key == "SIZE" ? have_sizes : key == "TYPE" ? have_types : have_counts) = true;
    } else if (key == "WIDTH" || key == "HEIGHT" || key == "POINTS") {
      std::size_t v = 0;
      if (n != 1 || !parse_size(tokens[1], v)) fail(line_no, std::string(key) + " is invalid");
      if (key == "WIDTH") h.width = v;
      if (key == "HEIGHT") h.height = v;
      if (key == "POINTS") {
        h.points = v;
        h.has_points = true;
      }
    } else if (key == "VIEWPOINT") {
      double v[7];
      if (n != 7) fail(line_no, "VIEWPOINT needs 7 values");
      for (int i = 0; i < 7; ++i) {
        if (!parse_double(tokens[i + 1], v[i])) fail(line_no, "VIEWPOINT value is not a number");
      }
      h.viewpoint = Eigen::Vector3f(static_cast<float>(v[0]), static_cast<float>(v[1]),
                                    static_cast<float>(v[2]));
    } else if (key == "DATA") {
      if (n != 1) fail(line_no, "DATA needs one value");
      h.data = std::string(tokens[1]);
      h.data_line = line_no;
      h.data_start = pos;
      break;
    } else {
      fail(line_no, "unknown header line '" + std::string(key) + "'");
    }
  }
  if (h.data.empty()) fail("no DATA line");
  if (h.fields.empty()) fail(h.data_line, "no FIELDS before DATA");
  if (h.data == "binary" && !(have_sizes && have_types)) {
    fail(h.data_line, "binary data needs SIZE and TYPE");
  }
  (void)have_counts;
  if (!h.has_points) {
    if (h.width > 0 && h.height > 0 && h.width > SIZE_MAX / h.height)
      fail("WIDTH*HEIGHT overflows");
    h.points = h.width * h.height;
  } else if (h.width > 0 && h.height > 0 && h.width * h.height != h.points) {
    fail(h.data_line, "POINTS " + std::to_string(h.points) + " differs from WIDTH*HEIGHT " +
                          std::to_string(h.width * h.height));
  }
  return h;
}

void Parser::prepare(const Header& h, PcdScan& scan) {
  for (std::size_t i = 0; i < h.fields.size(); ++i) {
    const std::string& name = h.fields[i].name;
    const int idx = static_cast<int>(i);
    if (name == "x") x_ = idx;
    if (name == "y") y_ = idx;
    if (name == "z") z_ = idx;
    if (name == "label") label_ = idx;
    if (name == "prob") prob_ = idx;
  }
  if (x_ < 0 || y_ < 0 || z_ < 0) fail(h.data_line, "fields x, y and z are required");
  for (const int f : {x_, y_, z_, label_}) {
    if (f >= 0 && h.fields[static_cast<std::size_t>(f)].count != 1) {
      fail(h.data_line, "field " + h.fields[static_cast<std::size_t>(f)].name + " needs COUNT 1");
    }
  }
  if (prob_ >= 0) {
    const Field& f = h.fields[static_cast<std::size_t>(prob_)];
    if (f.type != 'F' || f.count < 2 || f.count > 65535) {
      fail(h.data_line, "field prob must be float with COUNT >= 2 (one per class)");
    }
    scan.cloud.num_classes = static_cast<std::uint16_t>(f.count);
  }
  scan.cloud.origin = h.viewpoint;
}

void Parser::read_ascii(const Header& h, PcdScan& scan) {
  std::size_t values = 0;
  std::vector<std::size_t> first(h.fields.size());
  for (std::size_t i = 0; i < h.fields.size(); ++i) {
    first[i] = values;
    values += h.fields[i].count;
  }
  const std::size_t k = prob_ >= 0 ? h.fields[static_cast<std::size_t>(prob_)].count : 0;
  // Reserve no more than the bytes could hold, whatever POINTS claims.
  const std::size_t room = (bytes_.size() - h.data_start) / 2 + 1;
  scan.cloud.points.reserve(std::min(h.points, room));
  std::size_t pos = h.data_start;
  std::size_t line_no = h.data_line;
  std::string_view line;
  std::vector<std::string_view> tokens;
  std::size_t read = 0;
  while (next_line(bytes_, pos, line)) {
    ++line_no;
    tokens = split(line);
    if (tokens.empty()) continue;
    if (read == h.points) fail(line_no, "more data lines than POINTS " + std::to_string(h.points));
    if (tokens.size() < values) {
      fail(line_no, "expected " + std::to_string(values) + " values, found " +
                        std::to_string(tokens.size()));
    }
    if (tokens.size() > values) ++scan.lines_with_extra_values;
    auto number = [&](std::size_t field, std::size_t j) {
      double v = 0;
      if (!parse_double(tokens[first[field] + j], v)) {
        fail(line_no, "field " + h.fields[field].name + ": '" +
                          std::string(tokens[first[field] + j]) + "' is not a number");
      }
      return v;
    };
    scan.cloud.points.emplace_back(static_cast<float>(number(static_cast<std::size_t>(x_), 0)),
                                   static_cast<float>(number(static_cast<std::size_t>(y_), 0)),
                                   static_cast<float>(number(static_cast<std::size_t>(z_), 0)));
    if (prob_ >= 0) {
      for (std::size_t j = 0; j < k; ++j) {
        scan.cloud.probabilities.push_back(
            static_cast<float>(number(static_cast<std::size_t>(prob_), j)));
      }
    } else if (label_ >= 0) {
      const double v = number(static_cast<std::size_t>(label_), 0);
      if (!(v >= 0.0 && v <= 65535.0) || v != static_cast<double>(static_cast<int>(v))) {
        fail(line_no, "label '" + std::string(tokens[first[static_cast<std::size_t>(label_)]]) +
                          "' is not an integer in [0, 65535]");
      }
      scan.cloud.labels.push_back(static_cast<std::uint16_t>(v));
    } else {
      scan.cloud.labels.push_back(0);
    }
    ++read;
  }
  if (read != h.points) {
    fail(line_no,
         "found " + std::to_string(read) + " data lines, POINTS says " + std::to_string(h.points));
  }
}

template <typename T>
double load(const char* p) {
  T v;
  std::memcpy(&v, p, sizeof(T));
  return static_cast<double>(v);
}

// One value of a binary field; the header check guarantees a supported type and size.
double binary_value(const Field& f, const char* p) {
  if (f.type == 'F') return f.size == 8 ? load<double>(p) : load<float>(p);
  if (f.type == 'U') {
    switch (f.size) {
      case 1:
        return load<std::uint8_t>(p);
      case 2:
        return load<std::uint16_t>(p);
      case 4:
        return load<std::uint32_t>(p);
      default:
        return load<std::uint64_t>(p);
    }
  }
  switch (f.size) {
    case 1:
      return load<std::int8_t>(p);
    case 2:
      return load<std::int16_t>(p);
    case 4:
      return load<std::int32_t>(p);
    default:
      return load<std::int64_t>(p);
  }
}

void Parser::read_binary(const Header& h, PcdScan& scan) {
  std::size_t stride = 0;
  std::vector<std::size_t> offset(h.fields.size());
  for (std::size_t i = 0; i < h.fields.size(); ++i) {
    const Field& f = h.fields[i];
    const bool ok = f.type == 'F' ? (f.size == 4 || f.size == 8)
                                  : (f.size == 1 || f.size == 2 || f.size == 4 || f.size == 8);
    if (!ok)
      fail(h.data_line, "field " + f.name + " has unsupported SIZE " + std::to_string(f.size));
    offset[i] = stride;
    stride += f.size * f.count;
  }
  const std::size_t available = bytes_.size() - h.data_start;
  if (h.points > available / stride || h.points * stride != available) {
    fail(h.data_line, "binary data has " + std::to_string(available) + " bytes, expected " +
                          std::to_string(h.points) + " points of " + std::to_string(stride));
  }
  const std::size_t k = prob_ >= 0 ? h.fields[static_cast<std::size_t>(prob_)].count : 0;
  scan.cloud.points.reserve(h.points);
  for (std::size_t i = 0; i < h.points; ++i) {
    const char* row = bytes_.data() + h.data_start + i * stride;
    auto value = [&](int field, std::size_t j) {
      const Field& f = h.fields[static_cast<std::size_t>(field)];
      return binary_value(f, row + offset[static_cast<std::size_t>(field)] + j * f.size);
    };
    scan.cloud.points.emplace_back(static_cast<float>(value(x_, 0)),
                                   static_cast<float>(value(y_, 0)),
                                   static_cast<float>(value(z_, 0)));
    if (prob_ >= 0) {
      for (std::size_t j = 0; j < k; ++j) {
        scan.cloud.probabilities.push_back(static_cast<float>(value(prob_, j)));
      }
    } else if (label_ >= 0) {
      const double v = value(label_, 0);
      if (!(v >= 0.0 && v <= 65535.0) || v != static_cast<double>(static_cast<int>(v))) {
        fail("point " + std::to_string(i) + ": label is not an integer in [0, 65535]");
      }
      scan.cloud.labels.push_back(static_cast<std::uint16_t>(v));
    } else {
      scan.cloud.labels.push_back(0);
    }
  }
}

PcdScan Parser::parse() {
  const Header h = read_header();
  PcdScan scan;
  prepare(h, scan);
  if (h.data == "ascii") {
    read_ascii(h, scan);
  } else if (h.data == "binary") {
    read_binary(h, scan);
  } else {
    fail(h.data_line, "DATA " + h.data + " is not supported (ascii or binary)");
  }
  return scan;
}

}  // namespace

PcdScan parse_pcd(std::string_view bytes, const std::string& name) {
  return Parser(bytes, name).parse();
}

PcdScan read_pcd(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw PcdError(path.string() + ": cannot open");
  const std::string bytes((std::istreambuf_iterator<char>(in)), {});
  PcdScan scan = parse_pcd(bytes, path.string());
  if (scan.lines_with_extra_values > 0) {
    common::logger("pcd")->warn(
        "{}: {} lines carry more values than the header declares; "
        "the extra values were ignored",
        path.string(), scan.lines_with_extra_values);
  }
  return scan;
}

std::string format_pcd(const common::LabeledCloud& cloud, PcdEncoding encoding) {
  const bool soft = cloud.has_probabilities();
  const std::size_t k = soft ? cloud.num_classes : 0;
  std::ostringstream out;
  out << "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\n";
  if (soft) {
    out << "FIELDS x y z prob\nSIZE 4 4 4 4\nTYPE F F F F\nCOUNT 1 1 1 " << k << "\n";
  } else {
    out << "FIELDS x y z label\nSIZE 4 4 4 4\nTYPE F F F U\nCOUNT 1 1 1 1\n";
  }
  out << "WIDTH " << cloud.size() << "\nHEIGHT 1\nVIEWPOINT " << cloud.origin.x() << ' '
      << cloud.origin.y() << ' ' << cloud.origin.z() << " 1 0 0 0\nPOINTS " << cloud.size()
      << "\nDATA " << (encoding == PcdEncoding::kAscii ? "ascii" : "binary") << "\n";
  if (encoding == PcdEncoding::kAscii) {
    out.precision(9);
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      const Eigen::Vector3f& p = cloud.points[i];
      out << p.x() << ' ' << p.y() << ' ' << p.z();
      if (soft) {
        for (std::size_t j = 0; j < k; ++j) out << ' ' << cloud.probabilities[i * k + j];
      } else {
        out << ' ' << cloud.labels[i];
      }
      out << '\n';
    }
    return out.str();
  }
  std::string bytes = out.str();
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    bytes.append(reinterpret_cast<const char*>(cloud.points[i].data()), 3 * sizeof(float));
    if (soft) {
      bytes.append(reinterpret_cast<const char*>(cloud.probabilities.data() + i * k),
                   k * sizeof(float));
    } else {
      const std::uint32_t label = cloud.labels[i];
      bytes.append(reinterpret_cast<const char*>(&label), sizeof(label));
    }
  }
  return bytes;
}

void write_pcd(const std::filesystem::path& path, const common::LabeledCloud& cloud,
               PcdEncoding encoding) {
  std::ofstream out(path, std::ios::binary);
  if (!out) throw PcdError(path.string() + ": cannot create");
  const std::string bytes = format_pcd(cloud, encoding);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!out) throw PcdError(path.string() + ": write failed");
}

}  // namespace semap::map_io
