#include "scenes/scene.h"

namespace flexure::scenes {

const char* toString(OutputKind k) {
  switch (k) {
    case OutputKind::Frame: return "frame";
    case OutputKind::Animation: return "animation";
    case OutputKind::Path: return "path";
    case OutputKind::Projection: return "projection";
  }
  return "frame";
}

std::optional<OutputKind> parseOutputKind(const std::string& text) {
  for (OutputKind k : {OutputKind::Frame, OutputKind::Animation, OutputKind::Path, OutputKind::Projection})
    if (text == toString(k)) return k;
  return std::nullopt;
}

bool isImageExtension(const std::string& ext) { return ext == "png" || ext == "svg" || ext == "pdf" || ext == "tex"; }
bool isSolidExtension(const std::string& ext) { return ext == "obj" || ext == "stl"; }

std::optional<OutputKind> outputKindOfExtension(const std::string& ext) {
  if (isImageExtension(ext) || isSolidExtension(ext)) return OutputKind::Frame;
  if (ext == "gif" || ext == "mp4") return OutputKind::Animation;
  if (ext == "json" || ext == "csv" || ext == "fold") return OutputKind::Path;
  return std::nullopt;
}

bool canWrite(OutputKind kind, const std::string& ext) {
  switch (kind) {
    case OutputKind::Frame: return isImageExtension(ext) || isSolidExtension(ext);
    case OutputKind::Animation: return ext == "gif" || ext == "mp4";
    case OutputKind::Path: return ext == "json" || ext == "csv" || ext == "fold";
    case OutputKind::Projection: return isImageExtension(ext) || ext == "gif" || ext == "mp4";
  }
  return false;
}

engine::RigidityOptions rigidityOptions(const Scene& scene) {
  engine::RigidityOptions opt;
  opt.rank_tolerance = scene.analysis.rank_tolerance;
  opt.seed = scene.analysis.seed;
  opt.max_homotopy_flexes = scene.analysis.max_homotopy_flexes;
  opt.motion_check_steps = scene.analysis.motion_check_steps;
  return opt;
}

engine::TrackerOptions trackerOptions(const Scene& scene, int steps) {
  engine::TrackerOptions opt;
  opt.steps = steps;
  opt.step_size = scene.motion.step_size;
  opt.seed = scene.motion.seed;
  opt.factorization.rank_tolerance = scene.analysis.rank_tolerance;
  opt.corrector.factorization = opt.factorization;
  return opt;
}

}  // namespace flexure::scenes
