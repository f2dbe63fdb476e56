#include "ret3d/core/yaml_reader.h"

#include <cmath>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "support/test_util.h"

namespace ret3d {
namespace {

// The message of the ConfigError thrown by `read`, or "" if none is thrown.
template <typename F>
std::string errorOf(F read) {
  try {
    read();
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

void expectHas(const std::string& message, const std::string& part) {
  EXPECT_NE(message.find(part), std::string::npos) << "'" << part << "' not in: " << message;
}

TEST(YamlReader, ReadsTypedValuesAndKeepsThoseNotGiven) {
  YamlReader r = YamlReader::parse("a: 2.5\nn: 3\nflag: false\nname: x\nlist: [1, 2]\nsection: {inner: 7}\n", "f.yaml");
  double a = 0, absent = 9;
  int n = 0, inner = 0;
  bool flag = true;
  std::string name;
  std::vector<int> list;
  EXPECT_TRUE(r.get("a", &a));
  EXPECT_FALSE(r.get("absent", &absent));
  r.get("n", &n);
  r.get("flag", &flag);
  r.get("name", &name);
  r.get("list", &list);
  YamlReader s = r.child("section");
  s.get("inner", &inner);
  s.finish();
  r.finish();
  EXPECT_DOUBLE_EQ(a, 2.5);
  EXPECT_DOUBLE_EQ(absent, 9);
  EXPECT_EQ(n, 3);
  EXPECT_FALSE(flag);
  EXPECT_EQ(name, "x");
  EXPECT_EQ(list, (std::vector<int>{1, 2}));
  EXPECT_EQ(inner, 7);
  // An empty document and an absent section read as nothing given.
  YamlReader empty = YamlReader::parse("", "f.yaml");
  YamlReader none = empty.child("section");
  EXPECT_FALSE(none.get("inner", &inner));
  none.finish();
  empty.finish();
}

TEST(YamlReader, UnknownKeysNameTheFileTheFullPathAndTheKnownKeys) {
  const std::string e = errorOf([] {
    YamlReader r = YamlReader::parse("model:\n  bev:\n    resolution: 0.2\n    resolutoin: 0.2\n", "cfg.yaml");
    YamlReader m = r.child("model");
    YamlReader b = m.child("bev");
    double res = 0, x = 0;
    b.get("resolution", &res);
    b.get("x_min", &x);
    b.finish();
  });
  expectHas(e, "cfg.yaml: key 'model.bev.resolutoin': unknown key (line 4; known keys: resolution, x_min)");
}

TEST(YamlReader, WrongTypesNameTheKeyTheValueAndTheLine) {
  auto read = [](const std::string& yaml, auto value) {
    return errorOf([&] {
      auto v = value;
      YamlReader::parse(yaml, "cfg.yaml").get("k", &v);
    });
  };
  expectHas(read("k: abc", 0.0), "cfg.yaml: key 'k': expected a number, not 'abc' (line 1)");
  expectHas(read("k: 2.5", 0), "key 'k': expected an integer, not '2.5'");
  expectHas(read("k: maybe", true), "expected true or false, not 'maybe'");
  expectHas(read("k: [a, b]", std::string()), "expected a string, not [a, b]");
  expectHas(read("x: 1\nk: [1, two]", std::vector<double>()), "key 'k[1]': expected a number, not 'two' (line 2)");
  expectHas(read("k: 3", std::vector<double>()), "expected a list of numbers, not '3'");
  expectHas(errorOf([] { YamlReader::parse("k: [1, 2", "cfg.yaml"); }), "cfg.yaml: not valid YAML: line 1");
  expectHas(errorOf([] { YamlReader::parse("- 1\n- 2\n", "cfg.yaml"); }), "cfg.yaml: expected a map, not [1, 2]");
  expectHas(errorOf([] { YamlReader::parse("s: 3", "cfg.yaml").child("s"); }), "key 's': expected a map, not '3'");
}

TEST(YamlReader, PerClassMapsByClassName) {
  YamlReader r = YamlReader::parse("gate: {Cyclist: 0.9, Car: 2}\ncounts: {Pedestrian: 4}\n", "cfg.yaml");
  PerClass<double> gate{1.0, 0.4, 0.6};
  EXPECT_TRUE(r.getPerClass("gate", &gate));
  EXPECT_DOUBLE_EQ(gate.car, 2.0);
  EXPECT_DOUBLE_EQ(gate.pedestrian, 0.4);  // not given: kept
  EXPECT_DOUBLE_EQ(gate[2], 0.9);          // index = label - 1
  std::vector<std::pair<ObjectClass, int>> counts{{ObjectClass::Car, 1}};
  r.getClassValues("counts", &counts);  // the classes given replace the list
  ASSERT_EQ(counts.size(), 1u);
  EXPECT_EQ(counts[0], std::make_pair(ObjectClass::Pedestrian, 4));
  r.finish();

  const std::string unknown = errorOf([] {
    PerClass<double> v;
    YamlReader::parse("gate:\n  Truck: 1\n", "cfg.yaml").getPerClass("gate", &v);
  });
  expectHas(unknown, "cfg.yaml: key 'gate.Truck': unknown class (line 2; classes: Car, Pedestrian, Cyclist)");
  const std::string not_map = errorOf([] {
    PerClass<double> v;
    YamlReader::parse("gate: 1.0", "cfg.yaml").getPerClass("gate", &v);
  });
  expectHas(not_map, "key 'gate': expected a map from class names (Car, Pedestrian, Cyclist) to numbers, not '1.0'");
  const std::string bad_value = errorOf([] {
    PerClass<double> v;
    YamlReader::parse("gate: {Car: far}", "cfg.yaml").getPerClass("gate", &v);
  });
  expectHas(bad_value, "key 'gate.Car': expected a number, not 'far'");
  const std::string bad_class = errorOf([] {
    std::vector<ObjectClass> v;
    YamlReader::parse("classes: [Car, Truck]", "cfg.yaml").getClasses("classes", &v);
  });
  expectHas(bad_class, "key 'classes[1]': unknown class 'Truck' (Car, Pedestrian, Cyclist)");
  EXPECT_THROW(PerClass<double>().at(ObjectClass::Unknown), std::invalid_argument);
}

TEST(YamlReader, RangesAndChoicesAreCheckedWithOneMessage) {
  enum class Head { Anchor, Center };
  YamlReader r = YamlReader::parse("p: 1.5\nn: 0\nhead: center\nbad: yolo\n", "cfg.yaml", "model");
  double p = 0;
  int n = 5;
  expectHas(errorOf([&] { r.get("p", &p, 0, 1); }), "cfg.yaml: key 'model.p': must lie in [0, 1], got 1.5");
  expectHas(errorOf([&] { r.get("n", &n, 1, YamlReader::kNoLimit); }), "key 'model.n': must be >= 1, got 0");
  expectHas(errorOf([&] { r.within("n", -3, -YamlReader::kNoLimit, -5); }), "must be <= -5, got -3");
  expectHas(errorOf([&] { r.within("n", std::nan(""), 0, 1); }), "got nan");
  Head head = Head::Anchor;
  EXPECT_TRUE(r.getChoice("head", &head, {{"anchor", Head::Anchor}, {"center", Head::Center}}));
  EXPECT_EQ(head, Head::Center);
  expectHas(errorOf([&] { r.getChoice("bad", &head, {{"anchor", Head::Anchor}, {"center", Head::Center}}); }),
            "key 'model.bad': must be anchor or center, not 'yolo'");
}

TEST(YamlReader, ListsOfMapsAndFreeKeys) {
  YamlReader r = YamlReader::parse("blocks: [{from: 1}, {from: 2, tpyo: 0}]\nnames: {b: {x: 1}, a: {x: 2}}\n", "f");
  std::vector<YamlReader> blocks = r.children("blocks");
  ASSERT_EQ(blocks.size(), 2u);
  double from = 0;
  blocks[1].get("from", &from);
  EXPECT_DOUBLE_EQ(from, 2.0);
  expectHas(errorOf([&] { blocks[1].finish(); }), "f: key 'blocks[1].tpyo': unknown key");
  YamlReader names = r.child("names");
  EXPECT_EQ(names.keys(), (std::vector<std::string>{"b", "a"}));  // document order
  EXPECT_TRUE(names.has("a"));
  EXPECT_TRUE(names.isMap("a"));
  EXPECT_FALSE(names.has("c"));
}

TEST(YamlReader, FilesThatCannotBeReadAreNamed) {
  expectHas(errorOf([] { YamlReader::load("/nonexistent/x.yaml"); }), "/nonexistent/x.yaml: cannot be read");
  test::TempDir dir;
  expectHas(errorOf([&] { YamlReader::load(dir.path()); }), "cannot be read");  // a directory
  std::ofstream(dir / "a.yaml") << "k: 4\n";
  int k = 0;
  YamlReader::load(dir / "a.yaml").get("k", &k);
  EXPECT_EQ(k, 4);
}

// An ablation config holds what it changes: `base:` (relative to the file) is read first and the file laid over it.
TEST(YamlReader, ABaseFileIsReadFirstAndTheFileOverridesItKeyByKey) {
  test::TempDir dir;
  std::filesystem::create_directories(dir / "sub");
  std::ofstream(dir / "root.yaml") << "model: {rounds: 4, radius: 2.0}\ntrain: {lr: 0.001, iou: {Car: 0.7}}\n";
  std::ofstream(dir / "sub/mid.yaml") << "base: ../root.yaml\nmodel: {rounds: 1}\nlist: [1, 2, 3]\n";
  std::ofstream(dir / "leaf.yaml") << "base: sub/mid.yaml\ntrain: {lr: 0.002}\nlist: [9]\n";
  YamlReader r = YamlReader::load(dir / "leaf.yaml");
  YamlReader model = r.child("model"), train = r.child("train");
  int rounds = 0;
  double radius = 0, lr = 0, car_iou = 0;
  std::vector<int> list;
  model.get("rounds", &rounds);
  model.get("radius", &radius);
  train.get("lr", &lr);
  train.child("iou").get("Car", &car_iou);
  r.get("list", &list);
  EXPECT_EQ(rounds, 1);               // the middle file's
  EXPECT_DOUBLE_EQ(radius, 2.0);      // the root's, kept beside the middle file's rounds
  EXPECT_DOUBLE_EQ(lr, 0.002);        // the leaf's
  EXPECT_DOUBLE_EQ(car_iou, 0.7);     // a nested map the leaf did not name
  EXPECT_EQ(list, std::vector<int>{9});  // a list is replaced whole
  EXPECT_FALSE(r.has("base"));
  // readConfigText (the relation configs' way in) gives the same merged document.
  YamlReader again = YamlReader::parse(readConfigText(dir / "leaf.yaml", "leaf"), "leaf");
  again.child("model").get("radius", &radius);
  EXPECT_DOUBLE_EQ(radius, 2.0);
}

TEST(YamlReader, ACycleOrAMissingBaseIsAnErrorNamingTheFiles) {
  test::TempDir dir;
  std::ofstream(dir / "a.yaml") << "base: b.yaml\nk: 1\n";
  std::ofstream(dir / "b.yaml") << "base: a.yaml\nk: 2\n";
  const std::string cycle = errorOf([&] { YamlReader::load(dir / "a.yaml"); });
  expectHas(cycle, "key 'base': the bases form a cycle");
  expectHas(cycle, "a.yaml -> ");
  expectHas(cycle, "b.yaml -> ");
  std::ofstream(dir / "self.yaml") << "base: self.yaml\n";
  expectHas(errorOf([&] { YamlReader::load(dir / "self.yaml"); }), "cycle");
  std::ofstream(dir / "orphan.yaml") << "base: gone.yaml\nk: 1\n";
  const std::string missing = errorOf([&] { YamlReader::load(dir / "orphan.yaml"); });
  expectHas(missing, "orphan.yaml: key 'base': the base file '" + (dir / "gone.yaml") + "' does not exist");
  std::ofstream(dir / "list.yaml") << "base: [x.yaml]\n";
  expectHas(errorOf([&] { YamlReader::load(dir / "list.yaml"); }), "key 'base': expected the path of a base file");
  // Without a file there is no folder to resolve a base from: parse() refuses it as an unknown key.
  YamlReader r = YamlReader::parse("base: a.yaml\n", "text");
  expectHas(errorOf([&] { r.finish(); }), "key 'base': unknown key");
}

}  // namespace
}  // namespace ret3d
