// Checkpoints of a render between passes (penumbra render --checkpoint / --checkpoint-every /
// --resume, docs/robustness.md): the film's exact sums, the integrator's own state, the pass the
// render stopped after and what the render is (so that another scene or setting is refused). A
// resumed render continues with the same passes and gives the uninterrupted image bit for bit.
#pragma once

#include <penumbra/integrator.h>

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace penumbra {

/// Where a resumed render continues: after `spp` complete samples per pixel (iterations), with the
/// next pass `pass_spp` samples long.
struct ResumePoint {
  int spp = 0;
  int pass_spp = 1;
};

/// What the core's render loop asks the runtime about checkpoints (the runtime's RenderContext
/// implements it; other contexts, as in tests, need not).
class CheckpointHost {
 public:
  /// When resuming: restores the integrator's state (after its begin_render()) and says where to go on.
  virtual std::optional<ResumePoint> resume(SampleIntegrator& integrator) = 0;
  /// After each complete pass (end_pass() done): may write a checkpoint.
  virtual void pass_complete(const ResumePoint& next, const SampleIntegrator& integrator) = 0;
  /// True once the render was asked to end after the current pass (SIGINT, SIGTERM).
  virtual bool stop_requested() const = 0;

 protected:
  ~CheckpointHost() = default;
};

/// What a checkpoint belongs to: the scene's fingerprint (scene_hash: every directive, parameter
/// and referenced file after command-line overrides) and a readable summary, compared field by
/// field so that a refusal says what differs.
struct CheckpointKey {
  std::string scene_hash;
  std::vector<std::pair<std::string, std::string>> fields;  // e.g. {"integrator", "bdpt"}
};

struct CheckpointData {
  CheckpointKey key;
  ResumePoint point;
  double seconds = 0.0;           // render time before the checkpoint
  uint64_t nonfinite = 0;         // discarded non-finite samples so far
  int32_t first_nonfinite[2] = {-1, -1};
  std::string film;               // FilmRgb::save bytes
  std::string integrator;         // SampleIntegrator::save_state bytes
};

/// StateWriter / StateReader over a byte string.
class ByteWriter final : public StateWriter {
 public:
  void write(const void* data, size_t bytes) override;
  std::string& bytes() { return bytes_; }

 private:
  std::string bytes_;
};

class ByteReader final : public StateReader {
 public:
  /// `what` names the data in errors ("checkpoint ckpt.bin: film state").
  ByteReader(const std::string& bytes, std::string what) : bytes_(bytes), what_(std::move(what)) {}
  void read(void* data, size_t bytes) override;
  bool at_end() const { return pos_ == bytes_.size(); }

 private:
  [[noreturn]] void mismatch(uint64_t got, uint64_t expected) override;
  const std::string& bytes_;
  std::string what_;
  size_t pos_ = 0;
};

/// Writes atomically (a temporary file in the same folder, renamed into place). Throws Error.
void write_checkpoint(const std::string& path, const CheckpointData& data);
/// Reads and checks a checkpoint against `expected`; throws Error naming the file and, for another
/// render's checkpoint, each field that differs.
CheckpointData read_checkpoint(const std::string& path, const CheckpointKey& expected);
/// Throws Error (naming `option`) unless a checkpoint can be written at `path`.
void check_checkpoint_path(const std::string& path, const std::string& option);

}  // namespace penumbra
