// MovieWriter: frames piped to ffmpeg come out as an H.264/yuv420p MP4 that ffprobe agrees with.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>

#include "render/movie_writer.hpp"

namespace fs = std::filesystem;
using namespace furrow::render;

namespace {
std::string run(const std::string& cmd) {
  std::string out;
  std::unique_ptr<FILE, int (*)(FILE*)> p(popen(cmd.c_str(), "r"), pclose);
  char buf[256];
  while (p && fgets(buf, sizeof buf, p.get())) out += buf;
  return out;
}

fs::path fresh_dir(const std::string& name) {
  fs::path d = fs::temp_directory_path() / ("furrow_movie_test_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

RgbImage gradient_frame(int w, int h, int k) {
  RgbImage img(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      uint8_t* p = img.at(x, y);
      p[0] = uint8_t((x * 255) / w);
      p[1] = uint8_t((y * 255) / h);
      p[2] = uint8_t(k * 25);
    }
  return img;
}
}  // namespace

TEST(MovieWriter, EncodesTenFramesAsH264Yuv420p) {
  const fs::path dir = fresh_dir("ten");
  const std::string path = (dir / "gradient.mp4").string();
  const int w = 160, h = 90;
  {
    MovieWriter mw(path, w, h, 10.0);
    for (int k = 0; k < 10; ++k) mw.add_frame(gradient_frame(w, h, k));
    EXPECT_FALSE(fs::exists(path)) << "the movie must appear only when finished";
    mw.finish();
    EXPECT_EQ(mw.frames_written(), 10);
  }
  ASSERT_TRUE(fs::exists(path));
  const std::string info = run("ffprobe -v error -select_streams v:0 -count_frames -show_entries "
                               "stream=codec_name,width,height,pix_fmt,nb_read_frames -of default=nw=1 '" + path + "'");
  EXPECT_NE(info.find("codec_name=h264"), std::string::npos) << info;
  EXPECT_NE(info.find("width=160"), std::string::npos) << info;
  EXPECT_NE(info.find("height=90"), std::string::npos) << info;
  EXPECT_NE(info.find("pix_fmt=yuv420p"), std::string::npos) << info;
  EXPECT_NE(info.find("nb_read_frames=10"), std::string::npos) << info;
  // No temporary or log files left behind.
  int entries = 0;
  for (auto& e : fs::directory_iterator(dir)) entries += e.is_regular_file();
  EXPECT_EQ(entries, 1);
  fs::remove_all(dir);
}

TEST(MovieWriter, RejectsOddSizesWithClearMessage) {
  const fs::path dir = fresh_dir("odd");
  try {
    MovieWriter mw((dir / "odd.mp4").string(), 161, 90, 10.0);
    FAIL() << "odd width accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("161x90"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("even"), std::string::npos) << e.what();
  }
  EXPECT_THROW(MovieWriter((dir / "odd2.mp4").string(), 160, 91, 10.0), std::invalid_argument);
  EXPECT_TRUE(fs::is_empty(dir));
  fs::remove_all(dir);
}

TEST(MovieWriter, NeverOverwritesAndLeavesNothingWhenAbandoned) {
  const fs::path dir = fresh_dir("keep");
  const std::string path = (dir / "m.mp4").string();
  { std::ofstream(path) << "previous"; }
  EXPECT_THROW(MovieWriter(path, 64, 64, 5.0), std::runtime_error);
  {
    MovieWriter mw((dir / "abandoned.mp4").string(), 64, 64, 5.0);
    mw.add_frame(gradient_frame(64, 64, 1));
    EXPECT_THROW(mw.add_frame(gradient_frame(32, 64, 1)), std::invalid_argument);
  }  // destroyed without finish(): no file, no temp
  int entries = 0;
  for (auto& e : fs::directory_iterator(dir)) entries += e.is_regular_file();
  EXPECT_EQ(entries, 1);
  fs::remove_all(dir);
}
