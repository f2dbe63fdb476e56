#include "ret3d/core/json_writer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

namespace ret3d {
namespace {

TEST(JsonWriter, OneLineObjectsArraysAndScalars) {
  JsonWriter json;
  json.beginObject("base").field("median_ms", 12.5).field("p95_ms", 1.0 / 3).endObject();
  json.beginArray("samples").beginObject().field("frame", 0).endObject().beginObject().field("frame", 10).endObject();
  json.endArray();
  json.field("ok", true).field("name", "a \"quoted\" \\ name").field("count", std::size_t{7});
  EXPECT_EQ(json.str(),
            "{\"base\": {\"median_ms\": 12.5, \"p95_ms\": 0.333333}, \"samples\": [{\"frame\": 0}, {\"frame\": 10}], "
            "\"ok\": true, \"name\": \"a \\\"quoted\\\" \\\\ name\", \"count\": 7}\n");
}

TEST(JsonWriter, FixedDecimalsAndWholeNumbersAsIntegers) {
  JsonWriter fixed({/*decimals=*/3});
  fixed.field("a", 2.0).field("b", 0.12345).field("n", 3);
  EXPECT_EQ(fixed.str(), "{\"a\": 2.000, \"b\": 0.123, \"n\": 3}\n");

  JsonWriter metrics({/*decimals=*/4, /*whole_as_integer=*/true, /*top_level_lines=*/true});
  metrics.field("count", 42.0).field("ap", 71.234567).field("bad", std::numeric_limits<double>::quiet_NaN());
  EXPECT_EQ(metrics.str(), "{\n  \"count\": 42,\n  \"ap\": 71.2346,\n  \"bad\": null\n}\n");
  EXPECT_EQ(JsonWriter({4, true, true}).str(), "{\n}\n");
}

TEST(JsonWriter, NonFiniteNumbersBecomeNull) {
  JsonWriter json;
  json.field("inf", std::numeric_limits<double>::infinity()).field("nan", std::nan(""));
  EXPECT_EQ(json.str(), "{\"inf\": null, \"nan\": null}\n");
}

TEST(JsonWriter, RefusesUnbalancedOrMisplacedElements) {
  JsonWriter open;
  open.beginObject("x");
  EXPECT_THROW(open.str(), std::logic_error);
  JsonWriter array;
  array.beginArray("a");
  EXPECT_THROW(array.field("k", 1.0), std::logic_error);  // an array holds no keyed members
  EXPECT_THROW(array.endObject(), std::logic_error);
  JsonWriter top;
  EXPECT_THROW(top.beginObject(), std::logic_error);  // the top level is an object: members need keys
  EXPECT_THROW(top.endObject(), std::logic_error);
}

TEST(JsonWriter, SaveCreatesTheFolderAndNamesAFileItCannotWrite) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "ret3d_json_writer_test" / "sub";
  std::filesystem::remove_all(dir.parent_path());
  JsonWriter json;
  json.field("k", 1);
  json.save((dir / "out.json").string());
  std::ifstream f(dir / "out.json");
  std::stringstream text;
  text << f.rdbuf();
  EXPECT_EQ(text.str(), "{\"k\": 1}\n");
  try {
    json.save(dir.string());  // a folder, not a file
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(dir.string()), std::string::npos) << e.what();
  }
  std::filesystem::remove_all(dir.parent_path());
}

}  // namespace
}  // namespace ret3d
