// core: hashing and atomic output.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdlib>
#include <cstring>

#include "core/atomic_file.hpp"
#include "core/child_process.hpp"
#include "core/timer.hpp"
#include "core/base64.hpp"
#include "core/error.hpp"
#include "core/length.hpp"
#include "core/sha256.hpp"
#include "support.hpp"

TEST(Sha256, MatchesFipsVectors) {
  EXPECT_EQ(diefill::sha256_hex(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(diefill::sha256_hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(diefill::sha256_hex("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  // A million 'a': crosses many blocks and the padding boundary.
  EXPECT_EQ(diefill::sha256_hex(std::string(1000000, 'a')),
            "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
}

// RFC 4648's test vectors, both ways, and a character outside the alphabet refused.
TEST(Base64, MatchesRfc4648Vectors) {
  const std::pair<const char*, const char*> vectors[] = {{"", ""},         {"f", "Zg=="},         {"fo", "Zm8="},
                                                         {"foo", "Zm9v"}, {"foob", "Zm9vYg=="}, {"fooba", "Zm9vYmE="},
                                                         {"foobar", "Zm9vYmFy"}};
  for (const auto& [plain, encoded] : vectors) {
    EXPECT_EQ(diefill::base64_encode(plain, std::strlen(plain)), encoded);
    std::vector<std::uint8_t> decoded;
    ASSERT_TRUE(diefill::base64_decode(encoded, decoded));
    EXPECT_EQ(std::string(decoded.begin(), decoded.end()), plain);
  }
  std::vector<std::uint8_t> decoded;
  EXPECT_FALSE(diefill::base64_decode("Zm9v!", decoded));
}

TEST(AtomicFile, ReplacesOnlyWhenComplete) {
  test::TempDir dir;
  const auto target = dir / "out.txt";
  diefill::write_file_atomic(target, "first");
  {
    diefill::PendingFile pending(target);
    test::write_text(pending.path(), "half-written");
    // Destroyed without commit: the earlier output stays and no temporary is left behind.
  }
  EXPECT_EQ(test::read_text(target), "first");
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()),
                          std::filesystem::directory_iterator()),
            1);
}

TEST(StagingFolder, ReplacesAnEarlierRunsFilesAndSubfolderWhole) {
  // A second run into the same folder: its files replace the first's, its subfolder replaces the
  // first's whole (a file only the first run wrote there is gone), other files stay.
  test::TempDir dir;
  const auto write = [&](const std::string& run, bool extra) {
    diefill::StagingFolder out(dir.path());
    std::filesystem::create_directories(out / "fem");
    diefill::write_file_atomic(out / "report.json", run);
    diefill::write_file_atomic(out.path() / "fem" / "fill.inp", run);
    if (extra) diefill::write_file_atomic(out.path() / "fem" / "compaction.inp", run);
    out.commit();
  };
  diefill::write_file_atomic(dir / "notes.txt", "the user's");
  write("first", true);
  write("second", false);
  EXPECT_EQ(test::read_text(dir / "report.json"), "second");
  EXPECT_EQ(test::read_text(dir.path() / "fem" / "fill.inp"), "second");
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "fem" / "compaction.inp"));
  EXPECT_EQ(test::read_text(dir / "notes.txt"), "the user's");
  std::size_t entries = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir.path())) ++entries;
  EXPECT_EQ(entries, 3u) << "no staging or set-aside folder left behind";
}

TEST(InputError, NamesFileFieldAndRemedy) {
  const diefill::InputError e("scene.toml", "simulation.duration", "must be positive", "Give a duration in seconds");
  EXPECT_STREQ(e.what(), "scene.toml: simulation.duration: must be positive. Give a duration in seconds");
}

// Work in a child process (core/child_process.hpp): its bytes come back whole, a crash or a throw
// there is a failed outcome in this process, and a stop ends a child that would run a minute
// within the poll's second.
TEST(ChildProcess, ReturnsTheBytesReportsACrashAndStopsOnRequest) {
  const std::vector<double> values = {1.5, -2.25, 1e300};
  const diefill::ChildResult done =
      diefill::run_in_child([&] { return diefill::ByteWriter().put(std::uint64_t(7)).put(values).take(); });
  ASSERT_EQ(done.outcome, diefill::ChildOutcome::done);
  diefill::ByteReader in(done.bytes);
  std::uint64_t seven = 0;
  std::vector<double> back;
  in.get(seven);
  in.get(back);
  EXPECT_TRUE(in.ok());
  EXPECT_EQ(seven, 7u);
  EXPECT_EQ(back, values);
  std::uint64_t past_the_end = 0;
  in.get(past_the_end);
  EXPECT_FALSE(in.ok());

  EXPECT_EQ(diefill::run_in_child([]() -> std::string { throw std::runtime_error("no"); }).outcome,
            diefill::ChildOutcome::failed);
  EXPECT_EQ(diefill::run_in_child([]() -> std::string { std::_Exit(9); }).outcome, diefill::ChildOutcome::failed);

  int polls = 0;
  diefill::Stopwatch clock;
  const diefill::ChildResult stopped = diefill::run_in_child(
      [] {
        ::sleep(60);
        return std::string("late");
      },
      {[&] { return ++polls >= 2; }, nullptr});
  EXPECT_EQ(stopped.outcome, diefill::ChildOutcome::stopped);
  EXPECT_TRUE(stopped.bytes.empty());
  EXPECT_LT(clock.seconds(), 10.0);
}

// Lengths typed with their unit: each unit's factor exact, spaces allowed, anything else refused.
TEST(Length, ReadsANumberWithItsUnitAndRefusesTheRest) {
  const auto mm_of = [](const char* text) { return diefill::parse_length(text).value().millimetres(); };
  EXPECT_EQ(mm_of("0.2mm"), 0.2);
  EXPECT_EQ(mm_of(" 0.2 mm "), 0.2);
  EXPECT_EQ(mm_of("2e-4m"), 0.2);
  EXPECT_EQ(mm_of("200um"), 200e-3);
  EXPECT_EQ(mm_of("200µm"), 200e-3);
  EXPECT_EQ(mm_of("1in"), 25.4);
  EXPECT_EQ(diefill::parse_length("40mm")->metres(), 40 * 1e-3);
  for (const char* bad : {"0.2", "mm", "0.2 furlong", "0.2mmm", "nan mm", "inf m", ""})
    EXPECT_FALSE(diefill::parse_length(bad).has_value()) << bad;
}
