// A minimal test harness: CHECK records failures and the run ends with the plain closing line
// "N passed, N failed" that CI reads. TOPOSPLINE_TEST_CASE=<name> runs only the test cases whose
// names contain <name> (to look at one while working on it).
#pragma once

#include <cstdio>
#include <cstdlib>
#include <functional>
#include <string>
#include <vector>

namespace testing_harness
{
struct Registry
{
  std::vector<std::pair<std::string, std::function<void()>>> Tests;
  int CurrentFailures = 0;
  static Registry& Get()
  {
    static Registry registry;
    return registry;
  }
};

inline int RunAll()
{
  Registry& r = Registry::Get();
  int passed = 0, failed = 0;
  const char* only = std::getenv("TOPOSPLINE_TEST_CASE");
  for (auto& test : r.Tests)
  {
    if (only && test.first.find(only) == std::string::npos)
    {
      continue;
    }
    r.CurrentFailures = 0;
    test.second();
    if (r.CurrentFailures == 0)
    {
      ++passed;
      std::printf("PASS %s\n", test.first.c_str());
    }
    else
    {
      ++failed;
      std::printf("FAIL %s\n", test.first.c_str());
    }
  }
  std::printf("%d passed, %d failed\n", passed, failed);
  return failed == 0 ? 0 : 1;
}

struct Registrar
{
  Registrar(const char* name, std::function<void()> fn) { Registry::Get().Tests.emplace_back(name, std::move(fn)); }
};
} // namespace testing_harness

#define TEST_CASE(name)                                                                                              \
  static void name();                                                                                                \
  static testing_harness::Registrar name##_registrar(#name, name);                                                   \
  static void name()

#define CHECK(condition)                                                                                             \
  do                                                                                                                 \
  {                                                                                                                  \
    if (!(condition))                                                                                                \
    {                                                                                                                \
      ++testing_harness::Registry::Get().CurrentFailures;                                                            \
      std::printf("  %s:%d: CHECK(%s) failed\n", __FILE__, __LINE__, #condition);                                    \
    }                                                                                                                \
  } while (0)

#define CHECK_EQ(a, b)                                                                                               \
  do                                                                                                                 \
  {                                                                                                                  \
    const auto va = (a);                                                                                             \
    const auto vb = (b);                                                                                             \
    if (!(va == vb))                                                                                                 \
    {                                                                                                                \
      ++testing_harness::Registry::Get().CurrentFailures;                                                            \
      std::printf("  %s:%d: %s == %s failed (%s vs %s)\n", __FILE__, __LINE__, #a, #b, std::to_string(va).c_str(), \
        std::to_string(vb).c_str());                                                                                 \
    }                                                                                                                \
  } while (0)
