#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>

#include "fvp/host/core/gnuplot.h"
#include "fvp/host/core/output_directory.h"
#include "fvp/host/core/subprocess.h"

namespace fs = std::filesystem;
using namespace fvp::host;

namespace {

fs::path freshDir(const std::string& name) {
  const fs::path dir = fs::path(::testing::TempDir()) / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

/// Sets an environment variable for the scope, restoring the old value after.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const char* value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old;
    ::setenv(name, value, 1);
  }
  ~ScopedEnv() {
    if (old_)
      ::setenv(name_, old_->c_str(), 1);
    else
      ::unsetenv(name_);
  }

 private:
  const char* name_;
  std::optional<std::string> old_;
};

const char* const kScript =
    "set terminal pngcairo size 200,100\nplot '-' using 1:2 with lines\n0 0\n1 1\ne\n";

TEST(RunProgram, PassesArgumentsVerbatimAndCollectsBothStreams) {
  // Shell syntax in an argument stays text: no shell ever sees it.
  const fs::path dir = freshDir("fvp_run_program");
  const std::string evil = "x'; touch " + (dir / "PWNED").string() + "; echo '";
  const SubprocessResult r = runProgram({"printf", "%s|", evil, "$HOME"}, "");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_EQ(r.stdout_text, evil + "|$HOME|");
  EXPECT_FALSE(fs::exists(dir / "PWNED"));
}

TEST(RunProgram, FeedsLargeInputWhileReadingLargeOutput) {
  // 4 MB through cat: both pipes fill many times over, so a writer that did not also read
  // would deadlock.
  std::string input(4 << 20, 'a');
  for (std::size_t i = 0; i < input.size(); i += 97) input[i] = char('a' + i % 26);
  const SubprocessResult r = runProgram({"cat"}, input);
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_EQ(r.stdout_text, input);
}

TEST(RunProgram, ReportsExitCodesAndAProgramThatStopsReading) {
  const SubprocessResult r = runProgram({"sh", "-c", "echo oops >&2; exit 3"}, "");
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_EQ(r.stderr_text, "oops\n");
  // `true` exits without reading 1 MB of input: EPIPE, not a SIGPIPE that kills us.
  EXPECT_EQ(runProgram({"true"}, std::string(1 << 20, 'x')).exit_code, 0);
}

TEST(RunProgram, AMissingProgramIsAnErrorNamingIt) {
  try {
    runProgram({"fvp-no-such-program"}, "");
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("cannot start 'fvp-no-such-program'"), std::string::npos);
  }
}

TEST(Gnuplot, DrawsIntoADirectoryWhoseNameHoldsShellAndGnuplotQuotes) {
  const fs::path root = freshDir("fvp_gnuplot_quotes");
  const fs::path dir = root / "x'; touch PWNED; echo '\" `id`";
  fs::create_directories(dir);
  const fs::path png = dir / "a'b.png";
  plotWithGnuplot(kScript, png, "test figure");
  std::ifstream in(png, std::ios::binary);
  std::string head(8, '\0');
  in.read(head.data(), 8);
  EXPECT_EQ(head, std::string("\x89PNG\r\n\x1a\n", 8));
  EXPECT_FALSE(fs::exists("PWNED"));
  EXPECT_FALSE(fs::exists(root / "PWNED"));
  // Only the figure: no script, log or temporary left beside it.
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1);
}

TEST(GnuplotText, AcceptsTheSafeSetQuotedAndRefusesEverythingElse) {
  EXPECT_EQ(gnuplotQuoted("fvp-octomap MAE"), "'fvp-octomap MAE'");
  EXPECT_EQ(gnuplotQuoted("a.b_c-d+e=f%g/h(i)[j]:k, 0 9 Z"), "'a.b_c-d+e=f%g/h(i)[j]:k, 0 9 Z'");
  EXPECT_EQ(gnuplotQuoted(""), "''");
  // Every byte outside the set, alone and inside an otherwise fine title.
  const std::string safe =
      "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789 ._-+=%/()[]:,";
  for (int b = 0; b < 256; ++b) {
    const std::string one(1, char(b));
    const bool expected = safe.find(char(b)) != std::string::npos;
    EXPECT_EQ(isGnuplotSafeText(one), expected) << "byte " << b;
    if (!expected) {
      EXPECT_THROW(gnuplotQuoted("wind" + one + "x"), std::invalid_argument) << b;
    }
  }
  EXPECT_TRUE(isGnuplotSafeText(std::string(kGnuplotTextMax, 'a')));
  EXPECT_FALSE(isGnuplotSafeText(std::string(kGnuplotTextMax + 1, 'a')));
  // The issue's injection: refused, and the message shows it without a newline or a quote
  // that could close anything.
  try {
    gnuplotQuoted("wind'\nsystem \"touch PWNED\"\n#");
    FAIL() << "expected the title to be refused";
  } catch (const std::invalid_argument& e) {
    const std::string m = e.what();
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
    EXPECT_NE(m.find("wind'\\x0asystem"), std::string::npos) << m;
  }
}

TEST(Gnuplot, AQuotedTitleIsTextEvenWhenItReadsLikeACommand) {
  // Characters of the safe set only, in gnuplot's command forms: inside single quotes they
  // are a title, so gnuplot draws it and runs nothing.
  const fs::path dir = freshDir("fvp_gnuplot_inert_title");
  const std::string text = "system(touch " + (dir / "PWNED").string() + ") load(x) [1:2]";
  ASSERT_TRUE(isGnuplotSafeText(text)) << text;
  const std::string script = "set terminal pngcairo size 200,150\nset title " +
                             gnuplotQuoted(text) + "\nplot x title " + gnuplotQuoted(text) + "\n";
  plotWithGnuplot(script, dir / "f.png", "test figure");
  EXPECT_TRUE(fs::exists(dir / "f.png"));
  EXPECT_FALSE(fs::exists(dir / "PWNED"));
}

TEST(Gnuplot, MissingGnuplotIsAnErrorAndWritesNothing) {
  const fs::path dir = freshDir("fvp_gnuplot_missing");
  const ScopedEnv path("PATH", "/nonexistent");
  EXPECT_THROW(plotWithGnuplot(kScript, dir / "f.png", "test figure"), std::runtime_error);
  EXPECT_TRUE(fs::is_empty(dir));
}

TEST(Gnuplot, AScriptErrorIsAnErrorWithGnuplotsMessage) {
  const fs::path dir = freshDir("fvp_gnuplot_error");
  try {
    plotWithGnuplot("set terminal pngcairo\nplot sin(x) with nonsense\n", dir / "f.png", "fig");
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("fig: gnuplot failed"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(fs::is_empty(dir));
}

TEST(OutputDirectory, CreatesAMissingDirectoryAndRefusesAFile) {
  const fs::path dir = freshDir("fvp_output_directory");
  prepareOutputDirectory(dir / "a" / "b", "--out");
  EXPECT_TRUE(fs::is_directory(dir / "a" / "b"));
  EXPECT_TRUE(fs::is_empty(dir / "a" / "b"));
  std::ofstream(dir / "file") << "x";
  try {
    prepareOutputDirectory(dir / "file", "--out");
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()),
              "--out '" + (dir / "file").string() + "': exists and is not a directory");
  }
  EXPECT_THROW(prepareOutputDirectory(dir / "file" / "sub", "--out"), std::runtime_error);
}

TEST(OutputDirectory, RemovesOnlyWhatAnEarlierRunWrote) {
  const fs::path dir = freshDir("fvp_stale_outputs");
  for (const char* name : {"result.json", "notes.txt", "views/007.png", "views/cover.png",
                           "views/12.jpg", "views/0001.png", "views/013.txt"}) {
    fs::create_directories((dir / name).parent_path());
    std::ofstream(dir / name) << "x";
  }
  fs::create_directories(dir / "report.md");  // a directory is never removed
  removeStaleOutputs(dir, {"result.json", "report.md", "missing.ply"}, {"views", "none"});
  EXPECT_FALSE(fs::exists(dir / "result.json"));
  EXPECT_FALSE(fs::exists(dir / "views/007.png"));
  EXPECT_FALSE(fs::exists(dir / "views/0001.png"));
  EXPECT_TRUE(fs::exists(dir / "notes.txt"));
  EXPECT_TRUE(fs::exists(dir / "views/cover.png"));
  EXPECT_FALSE(fs::exists(dir / "views/12.jpg"));  // overlays are numbered JPEGs
  EXPECT_TRUE(fs::exists(dir / "views/013.txt"));
  EXPECT_TRUE(fs::is_directory(dir / "report.md"));
}

TEST(OutputDirectory, NumberedFileNamesArePaddedToThreeDigits) {
  EXPECT_EQ(numberedFileName("views", 7, "png"), "views/007.png");
  EXPECT_EQ(numberedFileName("overlays", 42, "jpg"), "overlays/042.jpg");
  EXPECT_EQ(numberedFileName("views", 1234, "png"), "views/1234.png");
}

}  // namespace
