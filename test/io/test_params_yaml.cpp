// FusionParams <-> YAML: every field round-trips, partial files override only what they name,
// typos and bad values are errors naming the key.
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <unistd.h>

#include "lidar_stereo_fusion/io/params_yaml.h"

namespace lidar_stereo_fusion {
namespace {

namespace fs = std::filesystem;

class YamlFile {
 public:
  explicit YamlFile(const std::string& text = "") {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    path_ = (fs::temp_directory_path() / ("lsf_params_" + std::string(info->name()) + "_" +
                                          std::to_string(::getpid()) + ".yaml"))
                .string();
    if (!text.empty()) std::ofstream(path_) << text;
  }
  ~YamlFile() { fs::remove(path_); }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

/// Every field set away from its default (and still valid).
FusionParams everyFieldChanged() {
  FusionParams p;
  p.method = Method::kLidarBF;
  p.projection.min_depth = 1.25;
  p.projection.max_depth = 90.5;
  p.bi.max_gap_px = 7;
  p.bi.max_jump_disp = 3.5;
  p.bi.max_disp_diff = 2.25;
  p.bi.max_color_diff = 45.0;
  p.bi.search_lines = 3;
  p.bi.max_interp_rows = 33;
  p.bf.radius = 4;
  p.bf.sigma_space = 2.5;
  p.bf.sigma_range = 1.75;
  p.bf.min_support = 2;
  PatchMatchParams& m = p.patchmatch;
  m.window_radius = 9;
  m.window_stride = 3;
  m.weight_delta = 12.5;
  m.alpha = 0.25;
  m.beta = 0.125;
  m.gamma = 0.625;
  m.lambda_col = 11.0;
  m.lambda_grad = 3.0;
  m.lambda_disp = 4.5;
  m.iterations = 5;
  m.slanted = false;
  m.init_from_prior = false;
  m.init_normal_from_prior = false;
  m.use_lidar_bounds = false;
  m.bound_margin = 0.75;
  m.min_refine_range = 0.5;
  m.min_disparity = 2.0;
  m.max_disparity = 100.0;
  m.view_propagation = false;
  m.lr_check = false;
  m.lr_max_diff = 1.5;
  m.median_radius = 7;
  m.confidence_weighting = false;
  m.lock_confidence = 0.75;
  m.fill_confidence = 0.25;
  m.coarse_scale = 3;
  m.coarse_levels = 3;
  m.full_size_unbounded = true;
  m.unbounded_scale = 9;  // coarse_scale^2
  m.search_scale = 3;
  m.skip_inconsistent = false;
  m.intermediate_refine = false;
  m.full_search_pixels = 123456;
  m.fine_iterations = 2;
  m.fine_refine_range = 1.5;
  p.confidence.edge_tolerance = 0.25;
  p.confidence.edge_sigma = 2.5;
  p.confidence.max_surface_slope = 0.5;
  p.confidence.removed_factor = 0.5;
  p.confidence.near_rows = 3.0;
  p.confidence.decay_rows = 8.0;
  p.confidence.hole_confidence = 0.125;
  m.num_threads = 3;
  m.seed = 18446744073709551557ull;  // beyond int32 and double precision
  return p;
}

void expectSame(const FusionParams& a, const FusionParams& b) {
  EXPECT_EQ(a.method, b.method);
  EXPECT_EQ(a.projection.min_depth, b.projection.min_depth);
  EXPECT_EQ(a.projection.max_depth, b.projection.max_depth);
  EXPECT_EQ(a.bi.max_gap_px, b.bi.max_gap_px);
  EXPECT_EQ(a.bi.max_jump_disp, b.bi.max_jump_disp);
  EXPECT_EQ(a.bi.max_disp_diff, b.bi.max_disp_diff);
  EXPECT_EQ(a.bi.max_color_diff, b.bi.max_color_diff);
  EXPECT_EQ(a.bi.search_lines, b.bi.search_lines);
  EXPECT_EQ(a.bi.max_interp_rows, b.bi.max_interp_rows);
  EXPECT_EQ(a.bf.radius, b.bf.radius);
  EXPECT_EQ(a.bf.sigma_space, b.bf.sigma_space);
  EXPECT_EQ(a.bf.sigma_range, b.bf.sigma_range);
  EXPECT_EQ(a.bf.min_support, b.bf.min_support);
  const PatchMatchParams &x = a.patchmatch, &y = b.patchmatch;
  EXPECT_EQ(x.window_radius, y.window_radius);
  EXPECT_EQ(x.window_stride, y.window_stride);
  EXPECT_EQ(x.weight_delta, y.weight_delta);
  EXPECT_EQ(x.alpha, y.alpha);
  EXPECT_EQ(x.beta, y.beta);
  EXPECT_EQ(x.gamma, y.gamma);
  EXPECT_EQ(x.lambda_col, y.lambda_col);
  EXPECT_EQ(x.lambda_grad, y.lambda_grad);
  EXPECT_EQ(x.lambda_disp, y.lambda_disp);
  EXPECT_EQ(x.iterations, y.iterations);
  EXPECT_EQ(x.slanted, y.slanted);
  EXPECT_EQ(x.init_from_prior, y.init_from_prior);
  EXPECT_EQ(x.init_normal_from_prior, y.init_normal_from_prior);
  EXPECT_EQ(x.use_lidar_bounds, y.use_lidar_bounds);
  EXPECT_EQ(x.bound_margin, y.bound_margin);
  EXPECT_EQ(x.min_refine_range, y.min_refine_range);
  EXPECT_EQ(x.min_disparity, y.min_disparity);
  EXPECT_EQ(x.max_disparity, y.max_disparity);
  EXPECT_EQ(x.view_propagation, y.view_propagation);
  EXPECT_EQ(x.lr_check, y.lr_check);
  EXPECT_EQ(x.lr_max_diff, y.lr_max_diff);
  EXPECT_EQ(x.median_radius, y.median_radius);
  EXPECT_EQ(x.confidence_weighting, y.confidence_weighting);
  EXPECT_EQ(x.lock_confidence, y.lock_confidence);
  EXPECT_EQ(x.fill_confidence, y.fill_confidence);
  EXPECT_EQ(x.coarse_scale, y.coarse_scale);
  EXPECT_EQ(x.coarse_levels, y.coarse_levels);
  EXPECT_EQ(x.full_size_unbounded, y.full_size_unbounded);
  EXPECT_EQ(x.skip_inconsistent, y.skip_inconsistent);
  EXPECT_EQ(x.unbounded_scale, y.unbounded_scale);
  EXPECT_EQ(x.search_scale, y.search_scale);
  EXPECT_EQ(x.intermediate_refine, y.intermediate_refine);
  EXPECT_EQ(x.full_search_pixels, y.full_search_pixels);
  EXPECT_EQ(x.fine_iterations, y.fine_iterations);
  EXPECT_EQ(x.fine_refine_range, y.fine_refine_range);
  const PriorConfidenceParams &c = a.confidence, &d = b.confidence;
  EXPECT_EQ(c.edge_tolerance, d.edge_tolerance);
  EXPECT_EQ(c.edge_sigma, d.edge_sigma);
  EXPECT_EQ(c.max_surface_slope, d.max_surface_slope);
  EXPECT_EQ(c.removed_factor, d.removed_factor);
  EXPECT_EQ(c.near_rows, d.near_rows);
  EXPECT_EQ(c.decay_rows, d.decay_rows);
  EXPECT_EQ(c.hole_confidence, d.hole_confidence);
  EXPECT_EQ(x.num_threads, y.num_threads);
  EXPECT_EQ(x.seed, y.seed);
}

/// The message of the runtime_error `load` throws ("" when none).
std::string loadError(const std::string& text) {
  YamlFile file(text);
  FusionParams p;
  try {
    loadParamsYaml(file.path(), p);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

TEST(ParamsYaml, EveryFieldRoundTrips) {
  const FusionParams changed = everyFieldChanged();
  changed.validate();
  YamlFile file;
  saveParamsYaml(file.path(), changed);
  FusionParams loaded;  // defaults
  loadParamsYaml(file.path(), loaded);
  expectSame(loaded, changed);
}

TEST(ParamsYaml, DefaultsRoundTripAndThirdDecimalsSurvive) {
  FusionParams p;
  p.patchmatch.alpha = 0.1;
  p.patchmatch.beta = 0.0;
  p.patchmatch.gamma = 0.9;  // 0.1 + 0.9 needs the exact doubles back
  YamlFile file;
  saveParamsYaml(file.path(), p);
  FusionParams loaded = everyFieldChanged();
  loadParamsYaml(file.path(), loaded);
  expectSame(loaded, p);
}

TEST(ParamsYaml, PartialRosparamStyleFileOverridesOnlyWhatItNames) {
  YamlFile file(
      "# a rosparam file: no %YAML directive\n"
      "method: pms\n"
      "projection: {max_depth: 120}\n"
      "patchmatch:\n"
      "  window_radius: 8\n"
      "  slanted: false\n"
      "  lr_check: 0\n"
      "  seed: 7\n");
  FusionParams p = everyFieldChanged();
  FusionParams expected = p;
  loadParamsYaml(file.path(), p);
  expected.method = Method::kPlainPMS;
  expected.projection.max_depth = 120.0;
  expected.patchmatch.window_radius = 8;
  expected.patchmatch.slanted = false;
  expected.patchmatch.lr_check = false;
  expected.patchmatch.seed = 7;
  expectSame(p, expected);
}

// One name per parameter (issue 10): the keys are the names of core/param_table.h at the top level,
// as rosparam and dynamic_reconfigure spell them; the former sections are still read.
TEST(ParamsYaml, TopLevelNamesAndTheDeprecatedSectionsGiveTheSameParameters) {
  YamlFile flat("method: pms\nmax_depth: 120\nwindow_radius: 7\nslanted: false\nseed: 7\n");
  YamlFile grouped(
      "method: pms\nprojection: {max_depth: 120}\n"
      "patchmatch: {window_radius: 7, slanted: false, seed: 7}\n");
  FusionParams a, b;
  loadParamsYaml(flat.path(), a);
  loadParamsYaml(grouped.path(), b);
  expectSame(a, b);
  EXPECT_EQ(a.patchmatch.window_radius, 7);
  EXPECT_EQ(a.projection.max_depth, 120.0);
  const std::string twice = loadError("window_radius: 7\npatchmatch: {window_radius: 6}\n");
  EXPECT_NE(twice.find("'window_radius' is given twice"), std::string::npos) << twice;
  const std::string wrong_group = loadError("bi: {window_radius: 6}\n");
  EXPECT_NE(wrong_group.find("'window_radius'"), std::string::npos) << wrong_group;
}

TEST(ParamsYaml, TheWriterUsesTheOneNames) {
  YamlFile file;
  saveParamsYaml(file.path(), everyFieldChanged());
  std::ifstream in(file.path());
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("\nwindow_radius: "), std::string::npos) << text;
  EXPECT_EQ(text.find("patchmatch:"), std::string::npos) << text;
}

TEST(ParamsYaml, CommentsAfterStringAndBooleanValuesAreIgnored) {
  YamlFile file(
      "method: lidar_bf   # the baseline\n"
      "patchmatch:\n"
      "  slanted: false   # front-parallel\n"
      "  lr_check: true # keep\n"
      "  seed: \"123\"  # quoted\n");
  FusionParams p;
  loadParamsYaml(file.path(), p);
  EXPECT_EQ(p.method, Method::kLidarBF);
  EXPECT_FALSE(p.patchmatch.slanted);
  EXPECT_TRUE(p.patchmatch.lr_check);
  EXPECT_EQ(p.patchmatch.seed, 123u);
}

// config/fusion.yaml says its values are the struct defaults.
TEST(ParamsYaml, TheShippedConfigLoadsAndKeepsTheDefaults) {
  FusionParams p;
  loadParamsYaml(std::string(LSF_SOURCE_DIR) + "/config/fusion.yaml", p);
  expectSame(p, FusionParams());
}

// config/paper.yaml is the paper's cost and constants; everything else stays at the defaults.
TEST(ParamsYaml, ThePaperPresetHasThePapersCostAndWindow) {
  FusionParams p;
  loadParamsYaml(std::string(LSF_SOURCE_DIR) + "/config/paper.yaml", p);
  EXPECT_EQ(p.method, Method::kFusedBI);
  EXPECT_FALSE(p.patchmatch.confidence_weighting);
  EXPECT_EQ(p.patchmatch.alpha, 0.1);
  EXPECT_EQ(p.patchmatch.beta, 0.0);
  EXPECT_EQ(p.patchmatch.gamma, 0.9);
  EXPECT_EQ(p.patchmatch.window_radius, 5);
  EXPECT_EQ(p.patchmatch.window_stride, 5);
  EXPECT_EQ(p.patchmatch.coarse_scale, 1);
  FusionParams expected;
  expected.patchmatch = p.patchmatch;  // the rest must be the defaults
  expectSame(p, expected);
}

// config/live.yaml cuts the search (issue 21); everything else stays at the defaults.
TEST(ParamsYaml, TheLivePresetCutsTheSearchOnly) {
  FusionParams p;
  loadParamsYaml(std::string(LSF_SOURCE_DIR) + "/config/live.yaml", p);
  EXPECT_EQ(p.method, Method::kFusedBI);
  EXPECT_EQ(p.patchmatch.search_scale, 2);
  EXPECT_FALSE(p.patchmatch.intermediate_refine);
  EXPECT_EQ(p.patchmatch.full_search_pixels, 200000);  // but not on images that small
  FusionParams expected;
  expected.patchmatch.search_scale = 2;
  expected.patchmatch.intermediate_refine = false;
  expected.patchmatch.full_search_pixels = 200000;
  expectSame(p, expected);
}

// accuracy_report's pms rows take the --params file as their base: plain PMS searches every
// pixel at full size, whatever the preset's levels (search_scale 2 once failed its validation).
TEST(ParamsYaml, PlainPmsOnTheLivePresetSearchesAtFullSize) {
  FusionParams p;
  loadParamsYaml(std::string(LSF_SOURCE_DIR) + "/config/live.yaml", p);
  const PatchMatchParams pms = FusionParams::plainPmsParams(p.patchmatch);
  EXPECT_EQ(pms.coarse_scale, 1);
  EXPECT_EQ(pms.search_scale, 1);
  EXPECT_EQ(pms.unbounded_scale, 1);
  p.method = Method::kPlainPMS;
  EXPECT_NO_THROW(FusionPipeline{p});
}

TEST(ParamsYaml, OpenCvStyleFileWithDirectiveAndEmptyFileAreAccepted) {
  YamlFile with_directive("%YAML:1.0\n---\nbi:\n  max_gap_px: 5\n  search_lines: 1\n");
  FusionParams p;
  loadParamsYaml(with_directive.path(), p);
  EXPECT_EQ(p.bi.max_gap_px, 5);
  EXPECT_EQ(p.bi.search_lines, 1);
  YamlFile empty("# nothing to change\n");
  FusionParams q = everyFieldChanged();
  loadParamsYaml(empty.path(), q);
  expectSame(q, everyFieldChanged());
}

/// Per case, a YAML text whose loading fails with each of the parts in the message.
void expectLoadErrors(const std::vector<std::pair<const char*, std::vector<std::string>>>& cases) {
  for (const auto& [yaml, said] : cases) {
    const std::string error = loadError(yaml);
    for (const auto& part : said) EXPECT_NE(error.find(part), std::string::npos) << error;
  }
}

TEST(ParamsYaml, UnknownKeysAreErrorsNamingTheKey) {
  expectLoadErrors({{"patchmatch:\n  window_radious: 5\n", {"'window_radious'", "patchmatch"}},
                    {"methd: pms\n", {"'methd'"}}});
}

TEST(ParamsYaml, WrongTypesAndInvalidValuesAreErrorsNamingTheKey) {
  expectLoadErrors({{"bf:\n  sigma_space: wide\n", {"'sigma_space'"}},   // not a number
                    {"bi:\n  max_gap_px: 2.5\n", {"'max_gap_px'"}},      // not an integer
                    {"patchmatch:\n  slanted: maybe\n", {"'slanted'"}},  // not a boolean
                    {"patchmatch:\n  seed: -1\n", {"'seed'"}},           // a negative seed
                    {"method: magic\n", {"magic"}},                      // no such method
                    {"bi: 3\n", {"'bi'"}},                               // a section that is no map
                    {"patchmatch:\n  window_radius: -2\n", {"window_radius"}}});  // validate()
}

TEST(ParamsYaml, ATopLevelSequenceIsAnErrorBeforeOpenCvParsesIt) {
  // OpenCV 4.6's parser never returns on these (found by fuzz_params_yaml in CI): a parameter
  // file is a map, so a top-level sequence is refused first, naming its line.
  for (const char* text : {"[m]\n.\n-", "[m]\nx\n-", "# c\n\n[m]\n.\n- ", "---\n- a\n"}) {
    const std::string error = loadError(text);
    EXPECT_NE(error.find("top level is not a map"), std::string::npos) << error;
  }
  EXPECT_NE(loadError("# c\n[m]\n.\n-").find("line 2"), std::string::npos);
  EXPECT_NE(loadError("[1, 2]\n").find("top level is not a map"), std::string::npos);
}

TEST(ParamsYaml, ContentOnADocumentMarkerLineIsAnErrorNamingTheLine) {
  // OpenCV's YAML parser loops forever on these (found by fuzzing; text_file.h): they must be
  // rejected before they reach it.
  for (const char* text :
       {"---hod: pms\npat--hod: pms\npatchmchm seed: \"71}\n", "---hod: pms\npat-hod: pms\nc: 1\n",
        "--- hod: pms\npat-hod: pms\nc: 1\n"}) {
    const std::string error = loadError(text);
    EXPECT_NE(error.find("line 1: '---'"), std::string::npos) << error;
  }
  const std::string end = loadError("method: pms\n... seed: 3\n");
  EXPECT_NE(end.find("line 2: '...'"), std::string::npos) << end;
  // After a document end only a new document ('---') may come: a '-' there loops the parser too
  // ("...\n-", found by fuzzing in CI), even indented or after blank and comment lines.
  for (const char* text : {"...\n-", "method: pms\n...\n- a\n", "...\n\n# c\n -x\n"}) {
    const std::string after = loadError(text);
    EXPECT_NE(after.find("content after the document end '...'"), std::string::npos) << after;
  }
  EXPECT_NE(loadError("method: pms\n...\n\n-\n").find("line 4"), std::string::npos);
  // A marker alone, or with blanks or a comment after it, is fine.
  for (const char* text :
       {"---\nmethod: pms\n", "---   \nmethod: pms\n", "--- # doc\nmethod: pms\n",
        "method: pms\n...\n", "method: pms\n...\n# end\n"}) {
    YamlFile alone(text);
    FusionParams p;
    EXPECT_NO_THROW(loadParamsYaml(alone.path(), p)) << text;
    EXPECT_EQ(p.method, Method::kPlainPMS) << text;
  }
}

TEST(ParamsYaml, FailedLoadLeavesParamsUntouchedAndMissingFileIsAnError) {
  YamlFile file("bi:\n  max_gap_px: 5\n  nonsense: 1\n");
  FusionParams p;
  EXPECT_THROW(loadParamsYaml(file.path(), p), std::runtime_error);
  EXPECT_EQ(p.bi.max_gap_px, BIParams().max_gap_px);
  EXPECT_THROW(loadParamsYaml("/nonexistent/params.yaml", p), std::runtime_error);
  EXPECT_THROW(saveParamsYaml("/nonexistent/dir/params.yaml", p), std::runtime_error);
}

}  // namespace
}  // namespace lidar_stereo_fusion
