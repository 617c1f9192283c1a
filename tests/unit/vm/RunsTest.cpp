// vm/Runs.h: every sequence comes back exactly, repeated structure is written in words that do not
// grow with its length, and malformed words are refused without reading past them.
#include <gtest/gtest.h>

#include <random>

#include "vm/Runs.h"

namespace qdot::bc::runs {
namespace {

class VectorSource : public WordSource {
 public:
  explicit VectorSource(const std::vector<uint32_t>& w) : words_(w) {}
  bool next(uint32_t& w) override { return at_ < words_.size() && (w = words_[at_++], true); }
  size_t read() const { return at_; }

 private:
  const std::vector<uint32_t>& words_;
  size_t at_ = 0;
};

std::vector<uint32_t> encoded(const std::vector<uint32_t>& v) {
  std::vector<uint32_t> words;
  encodeWords(v, words);
  return words;
}

// Decodes what encodeWords wrote and checks every word was used.
std::vector<uint32_t> roundTrip(const std::vector<uint32_t>& v) {
  std::vector<uint32_t> words = encoded(v), back;
  VectorSource in(words);
  EXPECT_TRUE(decodeWords(in, back));
  EXPECT_EQ(in.read(), words.size());
  return back;
}

// The row indices of the spring chain's Jacobian, column by column: x[j] and der(x[j]) each
// touch Euler-Lagrange rows j-1, j, j+1 and kinematic row n + j (boundaries have fewer).
std::vector<uint32_t> chainRows(uint32_t n) {
  std::vector<uint32_t> rows;
  for (int pass = 0; pass < 2; ++pass)
    for (uint32_t j = 0; j < n; ++j) {
      for (uint32_t r = j == 0 ? 0 : j - 1; r <= std::min(j + 1, n - 1); ++r) rows.push_back(r);
      rows.push_back(n + j);
    }
  return rows;
}

TEST(Runs, SequencesComeBackExactly) {
  std::mt19937 rng(7);
  std::vector<std::vector<uint32_t>> cases = {{}, {5}, {1, 2}, {7, 7, 7, 7, 7, 7, 7, 7, 7}, chainRows(3), chainRows(50)};
  std::vector<uint32_t> random(1000), wrapping, mixed;
  for (auto& x : random) x = rng();
  for (uint32_t t = 0; t < 40; ++t) wrapping.push_back(0xfffffff0u + 3 * t), wrapping.push_back(100 - 7 * t);
  for (int block = 0; block < 30; ++block) {  // runs of every period, literal stretches between them
    uint32_t p = 1 + rng() % 9, c = rng() % 6;
    std::vector<uint32_t> base(p), stride(p);
    for (uint32_t k = 0; k < p; ++k) base[k] = rng() % 100, stride[k] = rng() % 5 - 2;
    for (uint32_t t = 0; t < c; ++t)
      for (uint32_t k = 0; k < p; ++k) mixed.push_back(base[k] + t * stride[k]);
    for (uint32_t k = rng() % 4; k > 0; --k) mixed.push_back(rng());
  }
  cases.push_back(random), cases.push_back(wrapping), cases.push_back(mixed);
  for (const auto& v : cases) EXPECT_EQ(roundTrip(v), v) << v.size() << " values";
}

TEST(Runs, RepeatedStructureCostsWordsIndependentOfItsLength) {
  EXPECT_EQ(encoded(chainRows(1000)).size(), encoded(chainRows(100000)).size());
  EXPECT_LT(encoded(chainRows(100000)).size(), 64u);
  std::vector<uint32_t> starts;  // CSC column starts: 0, 3, 7, 11, …
  for (uint32_t j = 0; j < 50000; ++j) starts.push_back(j == 0 ? 0 : 3 + 4 * (j - 1));
  EXPECT_LT(encoded(starts).size(), 16u);
  std::vector<uint32_t> code;  // straight-line code of 20 words per element: registers and slots move
  for (uint32_t e = 0; e < 20000; ++e)
    for (uint32_t w = 0; w < 20; ++w) code.push_back(w % 3 == 0 ? 7 + w : w % 3 == 1 ? 5 * e + w : 1000 - e);
  EXPECT_EQ(roundTrip(code), code);
  EXPECT_LT(encoded(code).size(), 50u);
  std::mt19937 rng(3);
  std::vector<uint32_t> random(5000);
  for (auto& x : random) x = rng();
  EXPECT_LE(encoded(random).size(), random.size() + 3);  // no run pays: one literal block
}

TEST(Runs, MalformedWordsAreRefused) {
  std::vector<std::vector<uint32_t>> bad = {
      {},                           // no count
      {3, 0, 4, 1, 2, 3, 4},        // a literal longer than the sequence
      {3, 0, 0},                    // an empty literal
      {4, 1, 1, 5, 1},              // a run of one period
      {4, 2, 9, 0, 0},              // period beyond kMaxPeriod (no pairs follow)
      {4, 3, 2, 0, 1, 0, 1},        // 6 values for 4
      {6, 3, 2, 0, 1},              // truncated pairs
      {kMaxValues + 1, 0, 1, 5},    // absurd count
      {2, 0, 1, 5},                 // ends before the second value
  };
  for (const auto& words : bad) {
    VectorSource in(words);
    std::vector<uint32_t> v;
    EXPECT_FALSE(decodeWords(in, v)) << ::testing::PrintToString(words);
  }
}

TEST(Runs, StringsAreTemplatesAndNumbers) {
  std::vector<std::string> names;
  for (int i = 1; i <= 300; ++i) names.push_back("x[" + std::to_string(i) + "]");
  for (int i = 1; i <= 300; ++i) names.push_back("der(x[" + std::to_string(i) + "])");
  for (int i = 1; i <= 100; ++i)
    for (const char* member : {".k", ".c", ".s0"}) names.push_back("links[" + std::to_string(i) + "]" + member);
  for (const char* odd : {"", "time", "x01", "y[0]", "M[2,10]", "z[1234567890]", "a9b", "ω[3]", "0", "007"})
    names.push_back(odd);
  StringTemplates t = splitStrings(names);
  std::vector<std::string> back;
  ASSERT_TRUE(joinStrings(t, back));
  EXPECT_EQ(back, names);
  // x[·], der(x[·]), links[·].k, .c and .s· (s0: two numbers), then one each for the rest, where
  // "x01", "007" and ten digits are text.
  EXPECT_EQ(t.templates.size(), 5u + 10u);
  EXPECT_EQ(t.templates[0], (StringTemplates::Template{"x[", "]"}));
  EXPECT_EQ(t.templates[4], (StringTemplates::Template{"links[", "].s", ""}));
  EXPECT_EQ(t.templates[7], (StringTemplates::Template{"x01"}));
  EXPECT_LT(encoded(t.templateOf).size() + encoded(t.numbers).size(), 80u);
}

TEST(Runs, MalformedTemplatesAreRefused) {
  StringTemplates t = splitStrings(std::vector<std::string>{"x[1]", "time"});
  std::vector<std::string> out;
  auto spoiled = t;
  spoiled.templateOf[0] = 5;
  EXPECT_FALSE(joinStrings(spoiled, out));
  spoiled = t;
  spoiled.numbers.push_back(3);  // "time" has no number
  EXPECT_FALSE(joinStrings(spoiled, out));
  spoiled = t;
  spoiled.templates[1].clear();  // not even text
  EXPECT_FALSE(joinStrings(spoiled, out));
  spoiled = t;
  spoiled.numbers[0] = 1000000000;  // ten digits are not a number of a name
  EXPECT_FALSE(joinStrings(spoiled, out));
  spoiled = t;
  spoiled.numbers.pop_back();
  EXPECT_FALSE(joinStrings(spoiled, out));
}

}  // namespace
}  // namespace qdot::bc::runs
