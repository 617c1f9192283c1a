// CsvWriter: numbers read back bit for bit (shortest round-trip text), header quoting, and rows
// that are on disk as soon as row() returns.
#include <gtest/gtest.h>

#include <unistd.h>
#include <bit>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>

#include "output/CsvWriter.h"

namespace qdot::rt {
namespace {

double parse(const std::string& text) {
  double v = 0;
  auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  EXPECT_EQ(ec, std::errc()) << text;
  EXPECT_EQ(end, text.data() + text.size()) << text;
  return v;
}

TEST(CsvNumbers, ShortestFormsOfFamiliarValues) {
  EXPECT_EQ(formatNumber(0.1), "0.1");
  EXPECT_EQ(formatNumber(1.0), "1");
  EXPECT_EQ(formatNumber(-2.5), "-2.5");
  EXPECT_EQ(formatNumber(1e-7), "1e-07");
  EXPECT_EQ(formatNumber(0.0), "0");
  EXPECT_EQ(formatNumber(-0.0), "-0");
  EXPECT_EQ(formatNumber(std::numeric_limits<double>::infinity()), "inf");
  EXPECT_EQ(formatNumber(std::numeric_limits<double>::quiet_NaN()), "nan");
}

TEST(CsvNumbers, EveryPrintedNumberReadsBackBitForBit) {
  std::vector<double> values = {1.0 / 3,
                                2.0 / 3,
                                std::numbers::pi,
                                1e-300,
                                5e-324,
                                1.7976931348623157e308,
                                0.1 + 0.2,
                                123456789.123456789,
                                -1e22,
                                std::nextafter(1.0, 2.0)};
  std::mt19937_64 random(42);
  for (int i = 0; i < 10000; ++i) {
    double v = std::bit_cast<double>(random());
    if (std::isfinite(v)) values.push_back(v);
  }
  for (double v : values) {
    std::string text = formatNumber(v);
    EXPECT_EQ(std::bit_cast<uint64_t>(parse(text)), std::bit_cast<uint64_t>(v)) << text;
    EXPECT_LE(text.size(), 24u);
  }
}

TEST(CsvWriter, HeaderQuotesNamesWithCommasAndQuotes) {
  std::ostringstream out;
  CsvWriter writer(out);
  std::vector<std::string> names = {"x", "der(x)", "q[1,2]", "say \"hi\""};
  writer.begin(names);
  writer.row(0.5, std::vector<double>{1, 2, 3, 0.25});
  writer.finish();
  EXPECT_EQ(out.str(), "time,x,der(x),\"q[1,2]\",\"say \"\"hi\"\"\"\n0.5,1,2,3,0.25\n");
}

TEST(CsvWriter, IdentifierHeaderForToolsThatTakeIdentifiersOnly) {
  std::ostringstream out;
  CsvWriter writer(out, ColumnNaming::Identifier);
  std::vector<std::string> names = {"x", "der(x)", "q[1,2]", "say \"hi\""};
  writer.begin(names);
  writer.row(0.5, std::vector<double>{1, 2, 3, 0.25});
  EXPECT_EQ(out.str(), "time,x,der_x,q_1_2,say_hi\n0.5,1,2,3,0.25\n");
}

TEST(ColumnNames, ModelicaNamesBecomeIdentifiers) {
  std::vector<std::string> names = {"x", "der(x)", "der(der(x))", "x[1]", "M[1,2]", "der(th[10])", "a.b", "2x", "E"};
  EXPECT_EQ(identifierNames(names), (std::vector<std::string>{"x", "der_x", "der_der_x", "x_1", "M_1_2", "der_th_10",
                                                              "a_b", "_2x", "E"}));
}

TEST(ColumnNames, CollisionsAreNumberedAndIdentifiersKeepTheirNames) {
  // der_x is the user's own name: it keeps it, and der(x) takes the next free one
  std::vector<std::string> names = {"der(x)", "der_x", "x[1]", "x(1)", "der_x_2", "time()"};
  EXPECT_EQ(identifierNames(names),
            (std::vector<std::string>{"der_x_3", "der_x", "x_1", "x_1_2", "der_x_2", "time_2"}));
}

TEST(CsvWriter, RowsAreOnDiskBeforeFinish) {
  auto path = std::filesystem::temp_directory_path() / ("qdot_csv_flush_" + std::to_string(::getpid()) + ".csv");
  auto writer = CsvWriter::openFile(path.string());
  writer->begin(std::vector<std::string>{"a"});
  writer->row(0, std::vector<double>{0.1});
  writer->row(0.1, std::vector<double>{1.0 / 3});
  std::ifstream in(path);  // a separate reader while the writer is still open
  std::stringstream content;
  content << in.rdbuf();
  EXPECT_EQ(content.str(), "time,a\n0,0.1\n0.1,0.3333333333333333\n");
  writer->finish();
  std::filesystem::remove(path);
}

TEST(CsvWriter, UnwritablePathIsAClearError) {
  try {
    CsvWriter::openFile("/nonexistent-directory/out.csv");
    FAIL() << "opened a file in a missing directory";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("cannot open /nonexistent-directory/out.csv"), std::string::npos);
  }
}

}  // namespace
}  // namespace qdot::rt
