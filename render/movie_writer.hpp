// H.264 movies from raw RGB frames piped to the ffmpeg command-line tool. The file appears only
// when finish() succeeds (written under a temporary name in the same directory, then renamed).
#pragma once
#include <string>
#include <sys/types.h>

#include "render/image_io.hpp"

namespace furrow::render {

class MovieWriter {
 public:
  // Starts ffmpeg. Throws std::invalid_argument for odd or non-positive sizes (yuv420p needs even
  // ones) or fps <= 0; std::runtime_error if `path` exists and overwrite is false, or ffmpeg
  // cannot be started.
  MovieWriter(const std::string& path, int width, int height, double fps, bool overwrite = false);
  // Kills ffmpeg and removes the temporary file unless finish() has succeeded.
  ~MovieWriter();
  MovieWriter(const MovieWriter&) = delete;
  MovieWriter& operator=(const MovieWriter&) = delete;

  // Throws if the image size differs from the movie's or ffmpeg has gone away (with its message).
  void add_frame(const RgbImage& frame);
  // Closes the stream, waits for ffmpeg and publishes the file. Throws with ffmpeg's message on
  // failure or when no frame was added.
  void finish();

  int frames_written() const { return frames_; }
  const std::string& path() const { return path_; }

 private:
  void abort_encoder();
  std::string ffmpeg_message() const;

  std::string path_, temp_path_, log_path_;
  int width_ = 0, height_ = 0;
  bool overwrite_ = false;
  int pipe_fd_ = -1;
  pid_t pid_ = -1;
  int frames_ = 0;
  bool finished_ = false;
};

}  // namespace furrow::render
