#pragma once
// The viewer's computations, without any window: from a ViewerState to a Frame (positions,
// normals, colours, overlay text). Results are cached per input version (the smoothing steps
// applied), method, k and neighbourhood, so that switching back to something already computed,
// or changing only the colour field, costs no fit. One thread at a time may call compute().
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <Eigen/Core>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "common/tool_input.h"
#include "pcl_ddg/features/local_fit.h"
#include "pcl_ddg/io/vertex_fields.h"
#include "pcl_ddg/render/color_map.h"
#include "pcl_ddg/render/mesh_render.h"
#include "viewer/viewer_state.h"

namespace pcl_ddg {
namespace viewer {

struct Frame {
  ViewerState state;                                  ///< what this frame shows
  std::shared_ptr<const Eigen::Matrix3Xd> positions;  ///< after state.steps
  std::shared_ptr<const Eigen::Matrix3Xd> normals;    ///< state.method's (NaN where none)
  Eigen::VectorXd field;                              ///< empty for "none"
  std::string field_label;                            ///< e.g. "mean curvature H (1/length)"
  ColorRange range;                                   ///< of the colour bar
  ColorMap color_map = ColorMap::Diverging;
  VertexColors colors;                ///< per vertex (grey for "none" and NaN)
  double glyph_length = 0.0;          ///< normal glyph length: h, at least 1 % of the size
  Eigen::Index glyph_every = 1;       ///< a glyph on every n-th point
  std::vector<std::string> warnings;  ///< shown on screen
  double compute_ms = 0.0;            ///< of this frame
  bool step_refused = false;          ///< the last smoothing step failed (see warnings)
};

class ViewerModel {
 public:
  /** Takes a loaded input. */
  ViewerModel(tools::ToolInput input, std::string path);

  const InputCapabilities& capabilities() const { return capabilities_; }
  const std::string& path() const { return path_; }
  bool isMesh() const { return static_cast<bool>(input_.topology); }
  const MeshTopology* topology() const { return input_.topology.get(); }
  const Eigen::Matrix3Xd& inputPositions() const { return *input_positions_; }
  /** Where the sensor was (a PCD's VIEWPOINT): clouds are first seen from there. */
  const SensorPose& sensorPose() const { return input_.sensor_pose; }
  /** An organized cloud (width x height grid): seen from its sensor. */
  bool organized() const { return input_.mesh.cloud.height > 1; }
  /** A LAS survey, or coordinates far from the origin (UTM): +z is up. */
  bool geographic() const { return input_.las || farFromOrigin(inputPositions()); }
  /** Mean edge length (meshes) or mean point spacing (clouds). */
  double spacing() const { return spacing_; }

  /** Everything the state asks for; throws only on a bug (failures become warnings). */
  Frame compute(const ViewerState& state);

 private:
  using Positions = std::shared_ptr<const Eigen::Matrix3Xd>;
  Positions positionsAfter(const std::vector<SmoothingStep>& steps,
                           std::vector<std::string>& warnings, bool& refused);
  /** Normals of a method on the surface after `version` steps (a cache key prefix). */
  std::shared_ptr<const Eigen::Matrix3Xd> normalsOf(NormalMethod method, const ViewerState& state,
                                                    const std::string& version,
                                                    const Positions& positions,
                                                    std::vector<std::string>& warnings);
  Eigen::VectorXd fieldOf(const ViewerState& state, const std::string& version,
                          const Positions& positions, const Eigen::Matrix3Xd& normals,
                          std::string& label, ColorMap& map, std::vector<std::string>& warnings);
  /** A pca or quadric fit with the state's k and neighbourhood, oriented as the tools do. */
  LocalFitResult fit(LocalFitMethod method, const ViewerState& state,
                     const LocalCloud& cloud) const;
  /** A version's positions about the input's local origin (every version shares it). */
  const LocalCloud& cloudOf(const std::string& version, const Positions& positions);

  tools::ToolInput input_;
  std::string path_;
  InputCapabilities capabilities_;
  VertexColors file_colors_;  ///< the file's own colours (capabilities_.has_colors)
  double spacing_ = 0.0;
  double diagonal_ = 0.0;  ///< of the input's bounding box
  /** Positions after each prefix of smoothing steps, keyed by the steps' description. */
  std::map<std::string, Positions> positions_;
  /** positions_'s "input;", held apart: the drawing thread reads it while a computation adds to
   *  the map. */
  Positions input_positions_;
  std::map<std::string, std::shared_ptr<const Eigen::Matrix3Xd>> normals_;
  std::map<std::string, Eigen::VectorXd> fields_;
  std::map<std::string, LocalCloud> clouds_;
};

}  // namespace viewer
}  // namespace pcl_ddg
