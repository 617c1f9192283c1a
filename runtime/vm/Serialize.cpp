// bc::serialize / bc::deserialize: a little-endian byte image of a Module (magic "QDBC", format
// version, then the fields in declaration order; strings are prefixed by a u32 count). Sequences
// that grow with the model (names, per-variable flags, the Jacobian pattern, code, index tables,
// locations) are written as runs (vm/Runs.h), so repeated structure is written once.
// Reading checks every length against the bytes left and validates the result.
#include <algorithm>
#include <bit>
#include <cstring>

#include "qdot/bytecode.h"
#include "vm/Runs.h"

namespace qdot::bc {
namespace {

constexpr uint8_t kMagic[4] = {'Q', 'D', 'B', 'C'};

class Writer {
 public:
  void u32(uint32_t v) {
    for (int i = 0; i < 4; ++i) bytes.push_back(static_cast<uint8_t>(v >> (8 * i)));
  }
  void f64(double d) {
    auto v = std::bit_cast<uint64_t>(d);
    for (int i = 0; i < 8; ++i) bytes.push_back(static_cast<uint8_t>(v >> (8 * i)));
  }
  void str(const std::string& s) {
    u32(static_cast<uint32_t>(s.size()));
    bytes.insert(bytes.end(), s.begin(), s.end());
  }
  template <class T> void words(const std::vector<T>& v) {
    std::vector<uint32_t> values(v.size()), encoded;
    std::transform(v.begin(), v.end(), values.begin(), [](T x) { return static_cast<uint32_t>(x); });
    runs::encodeWords(values, encoded);
    for (uint32_t w : encoded) u32(w);
  }
  void strings(const std::vector<std::string>& v) {
    runs::StringTemplates t = runs::splitStrings(v);
    u32(static_cast<uint32_t>(t.templates.size()));
    for (const auto& parts : t.templates) {
      u32(static_cast<uint32_t>(parts.size()));
      for (const std::string& part : parts) str(part);
    }
    words(t.templateOf);
    words(t.numbers);
  }
  std::vector<uint8_t> bytes;
};

class Reader {
 public:
  explicit Reader(std::span<const uint8_t> b) : b_(b) {}
  bool ok() const { return ok_; }
  bool atEnd() const { return pos_ == b_.size(); }

  uint32_t u32() {
    if (!need(4)) return 0;
    uint32_t v = 0;
    for (int i = 0; i < 4; ++i) v |= static_cast<uint32_t>(b_[pos_++]) << (8 * i);
    return v;
  }
  double f64() {
    if (!need(8)) return 0;
    uint64_t v = 0;
    for (int i = 0; i < 8; ++i) v |= static_cast<uint64_t>(b_[pos_++]) << (8 * i);
    return std::bit_cast<double>(v);
  }
  std::string str() {
    uint32_t n = u32();
    if (!need(n)) return {};
    std::string s(reinterpret_cast<const char*>(b_.data() + pos_), n);
    pos_ += n;
    return s;
  }
  // A count of elements each at least `minBytes` long (so a bad count cannot allocate wildly).
  uint32_t count(size_t minBytes) {
    uint32_t n = u32();
    return need(static_cast<size_t>(n) * minBytes, false) ? n : (ok_ = false, 0);
  }
  std::vector<std::string> strings() {
    runs::StringTemplates t;
    t.templates.resize(count(8));
    for (auto& parts : t.templates) {
      parts.resize(count(4));
      for (std::string& part : parts) part = str();
    }
    t.templateOf = words<uint32_t>();
    t.numbers = words<uint32_t>();
    std::vector<std::string> v;
    if (ok_ && !runs::joinStrings(t, v)) ok_ = false;
    return v;
  }
  template <class T> std::vector<T> words() {
    struct Source : runs::WordSource {
      Reader& r;
      explicit Source(Reader& reader) : r(reader) {}
      bool next(uint32_t& w) override { return r.need(4) && (w = r.u32(), true); }
    } source(*this);
    std::vector<uint32_t> values;
    if (!ok_ || !runs::decodeWords(source, values)) return ok_ = false, std::vector<T>{};
    return std::vector<T>(values.begin(), values.end());
  }

 private:
  bool need(size_t n, bool fail = true) {
    if (ok_ && b_.size() - pos_ >= n) return true;
    if (fail) ok_ = false;
    return false;
  }
  std::span<const uint8_t> b_;
  size_t pos_ = 0;
  bool ok_ = true;
};

void writeFunction(Writer& w, const Function& f) {
  w.u32(f.registerCount);
  w.u32(f.outputCount);
  w.u32(static_cast<uint32_t>(f.constants.size()));
  for (double c : f.constants) w.f64(c);
  w.words(f.code);
  w.words(f.sources);
  w.u32(static_cast<uint32_t>(f.loops.size()));
  for (const Loop& l : f.loops) w.u32(l.count), w.u32(static_cast<uint32_t>(l.first)), w.u32(static_cast<uint32_t>(l.stride)), w.u32(l.offsetTable);
  w.words(f.indexTable);
}

Function readFunction(Reader& r) {
  Function f;
  f.registerCount = r.u32();
  f.outputCount = r.u32();
  f.constants.resize(r.count(8));
  for (double& c : f.constants) c = r.f64();
  f.code = r.words<uint32_t>();
  f.sources = r.words<uint32_t>();
  f.loops.resize(r.count(16));
  for (Loop& l : f.loops)
    l.count = r.u32(), l.first = static_cast<int32_t>(r.u32()), l.stride = static_cast<int32_t>(r.u32()), l.offsetTable = r.u32();
  f.indexTable = r.words<uint32_t>();
  return f;
}

// The description's fields in declaration order.
void writeDescription(Writer& w, const ModelDescription& d) {
  w.str(d.name);
  for (const auto* names : {&d.variableNames, &d.parameterNames, &d.parameterDescriptions, &d.outputNames,
                            &d.invariantNames, &d.structuralParameters})
    w.strings(*names);
  for (const auto* ints : {&d.isDifferential, &d.fixed, &d.jacobianColumnStarts, &d.jacobianRowIndices,
                           &d.derivativeLinks, &d.differentiatedRowStarts, &d.differentiatedRows, &d.initialRows, &d.outputKinds})
    w.words(*ints);
  w.strings(d.initialRowLabels);
}

ModelDescription readDescription(Reader& r) {
  ModelDescription d;
  d.name = r.str();
  for (auto* names : {&d.variableNames, &d.parameterNames, &d.parameterDescriptions, &d.outputNames,
                      &d.invariantNames, &d.structuralParameters})
    *names = r.strings();
  for (auto* ints : {&d.isDifferential, &d.fixed, &d.jacobianColumnStarts, &d.jacobianRowIndices,
                     &d.derivativeLinks, &d.differentiatedRowStarts, &d.differentiatedRows, &d.initialRows, &d.outputKinds})
    *ints = r.words<int32_t>();
  d.initialRowLabels = r.strings();
  return d;
}

}  // namespace

std::vector<uint8_t> serialize(const Module& m) {
  Writer w;
  w.bytes.assign(kMagic, kMagic + 4);
  w.u32(kFormatVersion);
  writeDescription(w, m.description);
  for (const Function& f : m.functions) writeFunction(w, f);
  std::vector<std::string> labels, wheres, texts;
  for (const Location& l : m.locations) labels.push_back(l.label), wheres.push_back(l.where), texts.push_back(l.text);
  w.strings(labels), w.strings(wheres), w.strings(texts);
  return std::move(w.bytes);
}

Result<Module> deserialize(std::span<const uint8_t> bytes) {
  if (bytes.size() < 8 || std::memcmp(bytes.data(), kMagic, 4) != 0) return Error{"not qdot bytecode (no QDBC header)"};
  Reader r(bytes.subspan(4));
  if (uint32_t version = r.u32(); version != kFormatVersion)
    return Error{"bytecode format version " + std::to_string(version) + ", expected " + std::to_string(kFormatVersion)};
  Module m;
  m.description = SharedDescription(readDescription(r));
  for (Function& f : m.functions) f = readFunction(r);
  std::vector<std::string> labels = r.strings(), wheres = r.strings(), texts = r.strings();
  if (wheres.size() != labels.size() || texts.size() != labels.size()) return Error{"malformed bytecode module (locations)"};
  for (size_t k = 0; k < labels.size(); ++k) m.locations.push_back({std::move(labels[k]), std::move(wheres[k]), std::move(texts[k])});
  if (!r.ok() || !r.atEnd()) return Error{r.ok() ? "trailing bytes after the bytecode module" : "truncated bytecode module"};
  if (Status valid = validate(m); !valid) return Error{valid.error()};
  return m;
}

}  // namespace qdot::bc
