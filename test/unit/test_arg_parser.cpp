// Command-line parsing shared by the tools.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "alvio/common/arg_parser.h"
#include "alvio/common/error.h"

using namespace alvio;

namespace {
bool parse(ArgParser& args, std::vector<std::string> words) {
  words.insert(words.begin(), "prog");
  std::vector<char*> argv;
  for (std::string& w : words) argv.push_back(w.data());
  return args.parse(static_cast<int>(argv.size()), argv.data());
}
}  // namespace

TEST(ArgParser, RepeatedListOptionCollectsEveryValue) {
  ArgParser args("prog", "test");
  args.listOption("set", "overrides");
  ASSERT_TRUE(parse(args, {"--set", "a=1", "--set=b=2,c=3"}));
  EXPECT_EQ(args.get("set"), "a=1,b=2,c=3");
}

TEST(ArgParser, RepeatedPlainOptionKeepsTheLastValue) {
  ArgParser args("prog", "test");
  args.option("config", "file", "default.yaml");
  EXPECT_EQ(args.get("config"), "default.yaml");
  ASSERT_TRUE(parse(args, {"--config", "a.yaml", "--config", "b.yaml"}));
  EXPECT_EQ(args.get("config"), "b.yaml");
}

TEST(ArgParser, ErrorsNameTheOption) {
  ArgParser args("prog", "test");
  args.option("out", "folder", "", true);
  args.flag("quiet", "no bar");
  const auto message = [&](std::vector<std::string> words) {
    try {
      parse(args, words);
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(message({"--bogus"}).find("'--bogus'"), std::string::npos);
  EXPECT_NE(message({"--quiet=1", "--out", "x"}).find("'--quiet' takes no value"),
            std::string::npos);
  EXPECT_NE(message({"--quiet"}).find("missing required option '--out'"), std::string::npos);
  EXPECT_NE(message({"--out"}).find("'--out' needs a value"), std::string::npos);
  // The tools print "<program>: error: <message>": the message does not repeat the name.
  EXPECT_EQ(message({"--bogus"}).find("prog"), std::string::npos);
}
