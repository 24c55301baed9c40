#pragma once
// What the viewer shows, as plain data: the normal method, k, the neighbourhood, the colour field,
// the smoothing steps applied to the input, and how things are drawn. Keys and -do commands both
// become actions ("method=pca", "k+", "smooth=implicit:2") applied here, so that a key press and
// the equivalent command reach exactly the same state.
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "pcl_ddg/features/local_fit.h"
#include "pcl_ddg/surface/mesh_smoothing.h"

namespace pcl_ddg {
namespace viewer {

enum class NormalMethod { Uniform, Area, Angle, MeanCurvature, PCA, Quadric, Robust };
/** Umbrella: uniform weights averaged by degree (mesh_smoothing.h). */
enum class SmoothingWeights { Cotan, Uniform, Umbrella };

struct SmoothingStep {
  SmoothingScheme method = SmoothingScheme::Implicit;
  /** in h^2 (h: the mean edge length of the input); umbrella: without unit; Taubin: unused
   *  (lambda 0.5, mu -0.53, averaged by degree) */
  double time_step = 1.0;
  SmoothingWeights weights = SmoothingWeights::Cotan;
  bool frozen = false;  ///< weights of the input kept, else rebuilt at every step
  bool operator==(const SmoothingStep& o) const {
    return method == o.method && time_step == o.time_step && weights == o.weights &&
           frozen == o.frozen;
  }
};

struct ViewerState {
  static constexpr int kDefaultK = 16;

  NormalMethod method = NormalMethod::Area;  ///< PCA on clouds (set by the model)
  int k = kDefaultK;
  NeighbourhoodKind neighbours = NeighbourhoodKind::MeshRings;
  /** none, rgb (the file's colours), mean, gauss, k1, k2, angle (to the reference method's
   *  normals), compare (mesh rings vs kd-tree), or the name of a scalar property of the file. */
  std::string field = "none";
  /** The normals field=angle compares with; unset: area on meshes, PCA on clouds (and, when that
   *  is the method shown, mean_curvature or quadric). */
  std::optional<NormalMethod> reference;
  std::vector<SmoothingStep> steps;  ///< applied to the input, in order
  double time_step = 1.0;            ///< of the next step (SmoothingStep::time_step)
  SmoothingWeights weights = SmoothingWeights::Cotan;  ///< of the next step
  bool frozen = true;                                  ///< of the next step (the library's default)
  bool show_normals = false;                           ///< glyphs
  bool smooth_shading = true;
  int screenshots = 0;  ///< taken so far (the next file's number)

  bool operator==(const ViewerState& o) const;
  bool operator!=(const ViewerState& o) const { return !(*this == o); }
};

/** What the input offers, for refusing actions that cannot apply (mesh methods on a cloud). */
struct InputCapabilities {
  bool is_mesh = false;
  int points = 0;
  std::vector<std::string> properties;  ///< scalar fields of the file (colourable)
  bool has_colors = false;              ///< the file's own colours (rgb, rgba, red green blue)
};

/** The initial state for an input: area normals on meshes, PCA through the kd-tree on clouds;
 *  the file's own colours (field=rgb) when it has them. */
ViewerState initialState(const InputCapabilities& input);

/**
 * Applies one action. The vocabulary (the same for keys and -do):
 *   method=uniform|area|angle|mean_curvature|pca|quadric|robust   method+ (the next one)
 *   k=N  k+  k-  k=default          neighbours=bfs|knn  neighbours+ (toggle)
 *   field=none|rgb|mean|gauss|k1|k2|angle|compare|<property>  field+ (the next one; rgb: the
 *   file's own colours, offered when it has them)
 *   reference=auto|<method>  (what field=angle compares with)
 *   smooth=explicit|implicit[:t]|taubin  (t: the step in h^2, umbrella: without unit)   undo
 *   step=t  step*  step/ (double, halve)   weights=cotan|uniform|umbrella  weights+ (the next)
 *   frozen=on|off  normals=on|off  normals+  shading=flat|smooth  shading+  screenshot
 * Throws std::invalid_argument with a message naming the action when it is unknown, malformed or
 * impossible for this input (a mesh method or bfs on a cloud, k beyond the point count).
 * Returns a note for the overlay when the action was adjusted (k clamped), else "".
 */
std::string applyAction(ViewerState& state, const InputCapabilities& input,
                        const std::string& action);

/** Splits a -do line (or a commands file's text) into actions: blank-separated, # comments. */
std::vector<std::string> splitActions(const std::string& text);

/** The action a key triggers, "" for keys the viewer leaves to PCLVisualizer. */
std::string actionForKey(const std::string& key_sym);

/** One line per key, for 'h' and -help. */
std::string keyHelp();

const char* methodName(NormalMethod method);
bool isMeshMethod(NormalMethod method);

/** Every normal method, in the order 'm' steps through them, with whether the input offers it
 *  (the mesh methods not on a cloud): the window lists them all and greys out the others. */
std::vector<std::pair<NormalMethod, bool>> methodsOffered(const InputCapabilities& input);

}  // namespace viewer
}  // namespace pcl_ddg
