#include "viewer/viewer_state.h"

#include <pcl/exceptions.h>

#include <algorithm>
#include <cstdlib>
#include <sstream>
#include <stdexcept>

#include "pcl_ddg/features/fit_choices.h"

namespace pcl_ddg {
namespace viewer {
namespace {

const std::vector<std::pair<NormalMethod, const char*>> kMethods = {
    {NormalMethod::Uniform, "uniform"}, {NormalMethod::Area, "area"},
    {NormalMethod::Angle, "angle"},     {NormalMethod::MeanCurvature, "mean_curvature"},
    {NormalMethod::PCA, "pca"},         {NormalMethod::Quadric, "quadric"},
    {NormalMethod::Robust, "robust"}};

const std::vector<std::string> kComputedFields = {"none", "mean",  "gauss",  "k1",
                                                  "k2",   "angle", "compare"};

// k changes by about a quarter, at least by 2: a few presses cover 4 .. 200.
int nextK(int k, bool up) {
  return up ? k + std::max(2, k / 4) : k - std::max(2, k / 5);
}

[[noreturn]] void refuse(const std::string& action, const std::string& why) {
  throw std::invalid_argument("'" + action + "': " + why);
}

double positiveNumber(const std::string& action, const std::string& text) {
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0' || !(value > 0.0) || value > 1e6) {
    refuse(action, "expected a positive number, got '" + text + "'");
  }
  return value;
}

// A two-way setting: "name+" toggles it, "name=on_value|off_value" sets it.
bool twoWay(bool current, bool toggle, const std::string& action, const std::string& value,
            const char* on_value, const char* off_value) {
  if (toggle) return !current;
  if (value != on_value && value != off_value) {
    refuse(action, std::string("expected ") + on_value + " or " + off_value);
  }
  return value == on_value;
}

std::vector<std::string> fieldsOf(const InputCapabilities& input) {
  std::vector<std::string> fields = kComputedFields;
  if (!input.is_mesh) fields.erase(std::find(fields.begin(), fields.end(), "compare"));
  if (input.has_colors) fields.insert(fields.begin() + 1, "rgb");  // after none
  fields.insert(fields.end(), input.properties.begin(), input.properties.end());
  return fields;
}

// The method of that name, refused when unknown or when it needs a mesh the input is not.
NormalMethod usableMethod(const InputCapabilities& input, const std::string& action,
                          const std::string& value) {
  const auto it = std::find_if(kMethods.begin(), kMethods.end(),
                               [&](const auto& m) { return value == m.second; });
  if (it == kMethods.end()) refuse(action, "unknown method");
  if (isMeshMethod(it->first) && !input.is_mesh) {
    refuse(action, std::string(it->second) + " normals need a mesh; this is a cloud");
  }
  return it->first;
}

}  // namespace

bool ViewerState::operator==(const ViewerState& o) const {
  return method == o.method && k == o.k && neighbours == o.neighbours && field == o.field &&
         reference == o.reference && steps == o.steps && time_step == o.time_step &&
         weights == o.weights && frozen == o.frozen && show_normals == o.show_normals &&
         smooth_shading == o.smooth_shading && screenshots == o.screenshots;
}

const char* methodName(NormalMethod method) {
  for (const auto& [m, name] : kMethods) {
    if (m == method) return name;
  }
  return "?";
}

bool isMeshMethod(NormalMethod method) {
  return method != NormalMethod::PCA && method != NormalMethod::Quadric &&
         method != NormalMethod::Robust;
}

std::vector<std::pair<NormalMethod, bool>> methodsOffered(const InputCapabilities& input) {
  std::vector<std::pair<NormalMethod, bool>> offered;
  for (const auto& [method, name] : kMethods)
    offered.emplace_back(method, input.is_mesh || !isMeshMethod(method));
  return offered;
}

ViewerState initialState(const InputCapabilities& input) {
  ViewerState state;
  if (!input.is_mesh) {
    state.method = NormalMethod::PCA;
    state.neighbours = NeighbourhoodKind::KdTree;
  }
  state.k = std::min(ViewerState::kDefaultK, std::max(3, input.points - 1));
  if (input.has_colors) state.field = "rgb";
  return state;
}

std::string applyAction(ViewerState& state, const InputCapabilities& input,
                        const std::string& action) {
  const std::size_t equals = action.find('=');
  const std::string name = action.substr(0, equals);
  const std::string value = equals == std::string::npos ? "" : action.substr(equals + 1);
  const auto needValue = [&] {
    if (equals == std::string::npos || value.empty()) refuse(action, "expected " + name + "=...");
  };

  if (action == "method+") {
    auto it = std::find_if(kMethods.begin(), kMethods.end(),
                           [&](const auto& m) { return m.first == state.method; });
    do {
      if (++it == kMethods.end()) it = kMethods.begin();
    } while (isMeshMethod(it->first) && !input.is_mesh);
    state.method = it->first;
  } else if (name == "method") {
    state.method = usableMethod(input, action, value);
  } else if (action == "k+" || action == "k-" || name == "k") {
    int k = state.k;
    if (action == "k+" || action == "k-") {
      k = nextK(state.k, action == "k+");
    } else if (value == "default") {
      k = ViewerState::kDefaultK;
    } else {
      needValue();
      char* end = nullptr;
      const long parsed = std::strtol(value.c_str(), &end, 10);
      if (*end != '\0' || parsed < 3 || parsed > 100000) refuse(action, "k must be 3 .. 100000");
      k = static_cast<int>(parsed);
    }
    const int most = std::max(3, input.points - 1);
    state.k = std::clamp(k, 3, most);
    if (state.k != k) return "k limited to " + std::to_string(state.k) + " (the input's size)";
  } else if (action == "neighbours+" || name == "neighbours") {
    NeighbourhoodKind next = state.neighbours == NeighbourhoodKind::MeshRings
                                 ? NeighbourhoodKind::KdTree
                                 : NeighbourhoodKind::MeshRings;
    if (name == "neighbours") {
      needValue();
      // The tools' names (bfs and knn: the former spellings); no pixel grid here.
      try {
        next = chooseNeighbourhood(value, true, false, kToolStyle);
      } catch (const pcl::BadArgumentException&) {
        refuse(action, "expected rings or kdtree");
      }
    }
    if (next == NeighbourhoodKind::MeshRings && !input.is_mesh)
      refuse(action, "mesh rings need a mesh");
    state.neighbours = next;
  } else if (action == "field+" || name == "field") {
    const std::vector<std::string> fields = fieldsOf(input);
    if (action == "field+") {
      auto it = std::find(fields.begin(), fields.end(), state.field);
      state.field = (it == fields.end() || it + 1 == fields.end()) ? fields.front() : *(it + 1);
    } else {
      needValue();
      if (std::find(fields.begin(), fields.end(), value) == fields.end()) {
        std::string known;
        for (const auto& f : fields) known += (known.empty() ? "" : "|") + f;
        refuse(action, "no such field (" + known + ")");
      }
      state.field = value;
    }
  } else if (name == "reference") {
    needValue();
    if (value == "auto") {
      state.reference.reset();
    } else {
      state.reference = usableMethod(input, action, value);
    }
  } else if (name == "smooth") {
    needValue();
    const std::size_t colon = value.find(':');
    const std::string scheme = value.substr(0, colon);
    if (scheme != "explicit" && scheme != "implicit" && scheme != "taubin")
      refuse(action, "expected explicit|implicit|taubin");
    if (!input.is_mesh) refuse(action, "smoothing needs a mesh");
    if (scheme == "taubin" && colon != std::string::npos)
      refuse(action, "a Taubin step takes no size (lambda 0.5, mu -0.53)");
    if (colon != std::string::npos)
      state.time_step = positiveNumber(action, value.substr(colon + 1));
    const SmoothingScheme method = scheme == "explicit" ? SmoothingScheme::Explicit
                                   : scheme == "taubin" ? SmoothingScheme::Taubin
                                                        : SmoothingScheme::Implicit;
    state.steps.push_back({method, state.time_step, state.weights, state.frozen});
  } else if (action == "undo") {
    if (!state.steps.empty()) state.steps.pop_back();
  } else if (name == "step" || action == "step*" || action == "step/") {
    if (action == "step*") {
      state.time_step = std::min(1e6, state.time_step * 2.0);
    } else if (action == "step/") {
      state.time_step = std::max(1e-6, state.time_step / 2.0);
    } else {
      needValue();
      state.time_step = positiveNumber(action, value);
    }
  } else if (action == "weights+") {
    state.weights = state.weights == SmoothingWeights::Cotan     ? SmoothingWeights::Uniform
                    : state.weights == SmoothingWeights::Uniform ? SmoothingWeights::Umbrella
                                                                 : SmoothingWeights::Cotan;
  } else if (name == "weights") {
    needValue();
    if (value == "cotan") {
      state.weights = SmoothingWeights::Cotan;
    } else if (value == "uniform") {
      state.weights = SmoothingWeights::Uniform;
    } else if (value == "umbrella") {
      state.weights = SmoothingWeights::Umbrella;
    } else {
      refuse(action, "expected cotan|uniform|umbrella");
    }
  } else if (action == "frozen+" || name == "frozen") {
    state.frozen = twoWay(state.frozen, action == "frozen+", action, value, "on", "off");
  } else if (action == "normals+" || name == "normals") {
    state.show_normals =
        twoWay(state.show_normals, action == "normals+", action, value, "on", "off");
  } else if (action == "shading+" || name == "shading") {
    state.smooth_shading =
        twoWay(state.smooth_shading, action == "shading+", action, value, "smooth", "flat");
  } else if (action == "screenshot") {
    ++state.screenshots;
  } else {
    refuse(action, "unknown action (see -help)");
  }
  return "";
}

std::vector<std::string> splitActions(const std::string& text) {
  std::vector<std::string> actions;
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    std::istringstream words(line.substr(0, line.find('#')));
    for (std::string word; words >> word;) actions.push_back(word);
  }
  return actions;
}

namespace {

struct KeyBinding {
  const char* key_sym;
  const char* label;
  const char* action;
  const char* what;
};

// PCLVisualizer keeps p w s j c f r q + - g u o l 1-9 h; these are free.
const KeyBinding kKeys[] = {
    {"m", "m", "method+",
     "next normal method (uniform area angle mean_curvature pca quadric robust)"},
    {"bracketright", "]", "k+", "more neighbours (k)"},
    {"bracketleft", "[", "k-", "fewer neighbours (k)"},
    {"backslash", "\\", "k=default", "k back to 16"},
    {"n", "n", "neighbours+", "neighbourhood: mesh rings <-> kd-tree (pca, quadric, robust)"},
    {"v", "v", "field+",
     "next colour field (none rgb mean gauss k1 k2 angle compare, properties; rgb: the file's "
     "colours)"},
    {"b", "b", "normals+", "normal glyphs on/off"},
    {"semicolon", ";", "shading+", "flat <-> smooth shading"},
    {"t", "t", "smooth=explicit", "one explicit smoothing step"},
    {"i", "i", "smooth=implicit", "one implicit smoothing step"},
    {"a", "a", "smooth=taubin", "one Taubin step (lambda 0.5, mu -0.53: no shrinkage)"},
    {"z", "z", "undo", "undo the last smoothing step"},
    {"period", ".", "step*", "double the step size"},
    {"comma", ",", "step/", "halve the step size"},
    {"y", "y", "weights+", "smoothing weights: cotan -> uniform -> umbrella"},
    {"d", "d", "frozen+", "smoothing weights frozen at the input <-> rebuilt every step"},
    {"F12", "F12", "screenshot", "screenshot to pcl_ddg_viewer_NNN.png"},
};

}  // namespace

std::string actionForKey(const std::string& key_sym) {
  for (const KeyBinding& key : kKeys) {
    if (key_sym == key.key_sym) return key.action;
  }
  return "";
}

std::string keyHelp() {
  std::ostringstream out;
  for (const KeyBinding& key : kKeys) {
    out << "  " << key.label
        << std::string(5 - std::min<std::size_t>(4, std::string(key.label).size()), ' ') << key.what
        << "  [" << key.action << "]\n";
  }
  out << "  PCLVisualizer's own keys (p w s j c f r q + - g u o l 1-9 h) work as in pcl_viewer.\n";
  return out.str();
}

}  // namespace viewer
}  // namespace pcl_ddg
