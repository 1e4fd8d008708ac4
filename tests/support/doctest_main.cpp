// The tests' main: doctest's own, plus two refusals. ctest runs each case by name
// (--test-case=NAME); a name that no longer matches (a ';' in it splits the ctest entry, a renamed
// case) would run nothing and pass: a run that passed no case through its filters fails instead. And
// a case that asserted nothing (a stub, an early return) fails: a test must be able to fail. Last,
// the files the cases registered (scratch_files.hpp) are removed if the run passed.
#define DOCTEST_CONFIG_IMPLEMENT
#include <doctest/doctest.h>

#include <cstdio>
#include <string>
#include <vector>

#include "scratch_files.hpp"

namespace {

unsigned g_cases_run = 0;
bool g_run_ended = false;
std::vector<std::string> g_assertless;  // cases that ran and asserted nothing

// Counts the cases that passed the filters, and notes those that asserted nothing.
struct FilterCount : doctest::IReporter {
  explicit FilterCount(const doctest::ContextOptions&) {}
  void report_query(const doctest::QueryData&) override {}
  void test_run_start() override {}
  void test_run_end(const doctest::TestRunStats& s) override {
    g_cases_run = s.numTestCasesPassingFilters;
    g_run_ended = true;
  }
  void test_case_start(const doctest::TestCaseData& tc) override { current_ = tc.m_name; }
  void test_case_reenter(const doctest::TestCaseData&) override {}
  void test_case_end(const doctest::CurrentTestCaseStats& s) override {
    if (s.numAssertsCurrentTest == 0) g_assertless.push_back(current_);
  }
  void test_case_exception(const doctest::TestCaseException&) override {}
  void subcase_start(const doctest::SubcaseSignature&) override {}
  void subcase_end() override {}
  void log_assert(const doctest::AssertData&) override {}
  void log_message(const doctest::MessageData&) override {}
  void test_case_skipped(const doctest::TestCaseData&) override {}

 private:
  std::string current_;
};

REGISTER_LISTENER("filter_count", 1, FilterCount);

int verdict(int result, const char* program) {
  if (g_cases_run == 0) {
    std::fprintf(stderr, "%s: no test case matches the filters given; nothing was tested\n", program);
    return result != 0 ? result : 1;
  }
  for (const std::string& name : g_assertless)
    std::fprintf(stderr, "%s: test case '%s' asserted nothing: it cannot fail\n", program, name.c_str());
  if (!g_assertless.empty()) return result != 0 ? result : 1;
  return result;
}

}  // namespace

int main(int argc, char** argv) {
  doctest::Context context(argc, argv);
  const int result = context.run();
  if (context.shouldExit() || !g_run_ended) return result;  // --help, --list-test-cases and the like
  const int code = verdict(result, argc > 0 ? argv[0] : "test");
  // The files the cases wrote: gone when the run passed, kept (and named) when it failed.
  exc::test::finish_scratch_files(code == 0);
  return code;
}
