// The small io helpers on synthetic input with exact answers: colour maps, progress bar, command
// line and the tools' main.
#include <algorithm>
#include <cmath>
#include <sstream>

#include <gtest/gtest.h>

#include "lidar_stereo_fusion/io/cli.h"
#include "lidar_stereo_fusion/io/progress.h"
#include "lidar_stereo_fusion/io/visualization.h"

namespace lidar_stereo_fusion {
namespace {

TEST(Visualization, EmptyPixelsAreBlackAndTheScaleFollowsTheMaximum) {
  cv::Mat1f d(1, 3, 0.f);
  d(0, 1) = 10.f;
  d(0, 2) = 20.f;
  const cv::Mat color = colorizeDisparity(d);
  ASSERT_EQ(color.type(), CV_8UC3);
  EXPECT_EQ(color.at<cv::Vec3b>(0, 0), cv::Vec3b(0, 0, 0));
  EXPECT_NE(color.at<cv::Vec3b>(0, 1), color.at<cv::Vec3b>(0, 2));
  // A fixed scale of 20 px: 20 maps to the same colour as in the automatic scale.
  EXPECT_EQ(colorizeDisparity(d, 20.0).at<cv::Vec3b>(0, 2), color.at<cv::Vec3b>(0, 2));

  const cv::Mat1f z = (cv::Mat1f(1, 3) << 0, 5, std::nanf(""));
  const cv::Mat depth = colorizeDepth(z, 80.0);
  EXPECT_EQ(depth.at<cv::Vec3b>(0, 0), cv::Vec3b(0, 0, 0));
  EXPECT_EQ(depth.at<cv::Vec3b>(0, 2), cv::Vec3b(0, 0, 0));
  EXPECT_NE(depth.at<cv::Vec3b>(0, 1), cv::Vec3b(0, 0, 0));

  const cv::Mat1f ref = (cv::Mat1f(1, 3) << 0, 10, 10);
  const cv::Mat1f est = (cv::Mat1f(1, 3) << 3, 10, 0);
  const cv::Mat error = colorizeError(est, ref, 5.0);
  EXPECT_EQ(error.at<cv::Vec3b>(0, 0), cv::Vec3b(0, 0, 0));  // no reference
  // Missing estimate shows as the maximum error, like an error of 5 px.
  EXPECT_EQ(
      error.at<cv::Vec3b>(0, 2),
      colorizeError((cv::Mat1f(1, 1) << 15), (cv::Mat1f(1, 1) << 10), 5.0).at<cv::Vec3b>(0, 0));
  EXPECT_THROW(colorizeError(est, cv::Mat1f(1, 2, 1.f)), std::invalid_argument);

  const cv::Mat overlay =
      overlaySparse(cv::Mat(5, 5, CV_8UC3, cv::Scalar::all(100)), cv::Mat1f(5, 5, 0.f));
  EXPECT_EQ(overlay.at<cv::Vec3b>(2, 2), cv::Vec3b(40, 40, 40));  // darkened to 40 %
  EXPECT_THROW(overlaySparse(cv::Mat(5, 5, CV_8UC3), cv::Mat1f(4, 5)), std::invalid_argument);
}

// --save-vis pictures carry their scale (issue 10): a colour bar below, in the picture's colours.
TEST(Visualization, ColourBarBelowThePictureGoesFromLevel0ToLevel255) {
  cv::Mat1f z(20, 400, 10.f);
  const cv::Mat picture = colorizeDepth(z, 80.0);
  const cv::Mat with_bar = withColorBar(picture, 80.0, 0.0, "m");
  ASSERT_EQ(with_bar.cols, picture.cols);
  ASSERT_GT(with_bar.rows, picture.rows + 10);
  EXPECT_EQ(cv::norm(with_bar(cv::Rect(0, 0, 400, 20)), picture, cv::NORM_INF), 0.0);
  cv::Mat1b level(1, 2);
  level(0, 0) = 0;
  level(0, 1) = 255;
  cv::Mat ends;
  cv::applyColorMap(level, ends, cv::COLORMAP_TURBO);
  const int margin = std::max(8, 400 / 40), bar_row = picture.rows + 4;
  EXPECT_EQ(with_bar.at<cv::Vec3b>(bar_row, margin), ends.at<cv::Vec3b>(0, 0));
  EXPECT_EQ(with_bar.at<cv::Vec3b>(bar_row, 400 - margin - 1), ends.at<cv::Vec3b>(0, 1));
  EXPECT_THROW(withColorBar(cv::Mat1b(2, 2), 0, 1, ""), std::invalid_argument);
}

// The live node's disparity_image_color scale: the frame's 99th percentile rounded up to 16 px.
TEST(Visualization, DisparityScaleIsThe99thPercentileRoundedUpTo16Px) {
  cv::Mat1f d(1, 102, 0.f);
  for (int i = 0; i < 100; ++i) d(0, i) = static_cast<float>(i + 1);  // 1 .. 100 px
  d(0, 100) = std::nanf("");                                          // no value, as 0
  EXPECT_EQ(disparityColorScale(d, 192.0), 112.0);  // 99th percentile 99 px -> 7 x 16
  EXPECT_EQ(disparityColorScale(d, 64.0), 64.0);    // never beyond the search range
  EXPECT_EQ(disparityColorScale(cv::Mat1f(2, 2, 0.f), 192.0), 16.0);   // no value: 16 px
  EXPECT_EQ(disparityColorScale(cv::Mat1f(2, 2, 0.5f), 192.0), 16.0);  // at least 16 px
  EXPECT_EQ(disparityColorScale(cv::Mat1f(2, 2, 32.f), 192.0), 32.0);  // a multiple stays
  const cv::Mat picture = disparityPicture(d, 192.0);
  ASSERT_GT(picture.rows, d.rows);
  EXPECT_EQ(cv::norm(picture(cv::Rect(0, 0, d.cols, 1)), colorizeDisparity(d, 112.0), cv::NORM_INF),
            0.0);
  const cv::Mat1f z = (cv::Mat1f(1, 3) << 0, 5, 40);
  EXPECT_EQ(cv::norm(depthPicture(z, 80.0), withColorBar(colorizeDepth(z, 80.0), 80.0, 0.0, "m"),
                     cv::NORM_INF),
            0.0);
}

TEST(ProgressBar, BarRateAndEta) {
  std::ostringstream out;
  ProgressBar bar(out, 4, false, 8);
  bar.update(2, "frame");
  EXPECT_EQ(out.str().substr(0, 22), "[====>   ] 2/4 frame  ");
  EXPECT_NE(out.str().find(" s/frame, ETA "), std::string::npos) << out.str();
  bar.update(4, "done");  // nothing left: no ETA
  EXPECT_EQ(out.str().find("ETA", out.str().find("4/4")), std::string::npos) << out.str();
}

TEST(CommandLine, OptionsFlagsAndErrors) {
  const char* argv[] = {"tool", "--frames", "3", "--save-vis", "--method", "pms"};
  const CommandLine cl(6, argv, {"--frames", "--method", "--out"}, {"--save-vis"});
  EXPECT_TRUE(cl.has("--save-vis"));
  EXPECT_FALSE(cl.has("--out"));
  EXPECT_EQ(cl.intValue("--frames", 0, 1, 10), 3);
  EXPECT_EQ(cl.value("--out", "x"), "x");
  EXPECT_EQ(cl.choice("--method", "fused_bi", {"fused_bi", "pms"}), "pms");
  EXPECT_THROW(cl.intValue("--frames", 0, 5, 10), UsageError);
  EXPECT_THROW(cl.choice("--method", "", {"fused_bi"}), UsageError);
  const char* unknown[] = {"tool", "--frame", "3"};
  EXPECT_THROW(CommandLine(3, unknown, {"--frames"}, {}), UsageError);
  const char* missing[] = {"tool", "--frames"};
  EXPECT_THROW(CommandLine(2, missing, {"--frames"}, {}), UsageError);
  const char* twice[] = {"tool", "--frames", "1", "--frames", "2"};
  EXPECT_THROW(CommandLine(5, twice, {"--frames"}, {}), UsageError);
  const char* junk[] = {"tool", "--frames", "3x"};
  EXPECT_THROW(CommandLine(3, junk, {"--frames"}, {}).intValue("--frames", 0, 0, 9), UsageError);
}

TEST(CommandLine, NumbersInARange) {
  const char* argv[] = {"tool", "--period", "0.1", "--scale", "2e1"};
  const CommandLine cl(5, argv, {"--period", "--scale", "--rate"}, {});
  EXPECT_EQ(cl.doubleValue("--period", 0.0, 0.001, 10.0), 0.1);
  EXPECT_EQ(cl.doubleValue("--scale", 0.0, 0.0, 100.0), 20.0);
  EXPECT_EQ(cl.doubleValue("--rate", 7.5, 0.0, 1.0), 7.5) << "absent: the fallback, unchecked";
  EXPECT_THROW(cl.doubleValue("--scale", 0.0, 0.0, 10.0), UsageError);
  for (const char* bad : {"0.1s", "nan", "inf", "", "-", "0x"}) {
    const char* junk[] = {"tool", "--period", bad};
    EXPECT_THROW(CommandLine(3, junk, {"--period"}, {}).doubleValue("--period", 0.0, -1e9, 1e9),
                 UsageError)
        << bad;
  }
  try {
    const char* low[] = {"tool", "--period", "0"};
    CommandLine(3, low, {"--period"}, {}).doubleValue("--period", 0.0, 0.001, 10.0);
    ADD_FAILURE() << "0 is below the range";
  } catch (const UsageError& e) {
    EXPECT_EQ(std::string(e.what()), "--period must be a number in [0.001, 10], got '0'");
  }
}

TEST(CommandLine, ToolMainHelpUsageErrorsAndTheExitStatus) {
  const char* help[] = {"tool", "--out", "x", "-h"};
  const char* plain[] = {"tool"};
  bool ran = false;
  testing::internal::CaptureStdout();
  EXPECT_EQ(toolMain("tool", "usage: tool\n", 4, help, [&] { return ran = true, 5; }), 0);
  EXPECT_EQ(testing::internal::GetCapturedStdout(), "usage: tool\n");
  EXPECT_FALSE(ran) << "--help runs nothing";
  EXPECT_TRUE(wantsHelp(4, help));
  EXPECT_FALSE(wantsHelp(1, plain));

  EXPECT_EQ(toolMain("tool", "usage: tool\n", 1, plain, [] { return 3; }), 3);
  testing::internal::CaptureStderr();
  EXPECT_EQ(toolMain("tool", "usage: tool\n", 1, plain,
                     []() -> int { throw UsageError("--frames needs a value"); }),
            2);
  EXPECT_EQ(testing::internal::GetCapturedStderr(),
            "tool: --frames needs a value\n\nusage: tool\n");
  testing::internal::CaptureStderr();
  EXPECT_EQ(toolMain("tool", "usage: tool\n", 1, plain,
                     []() -> int { throw std::runtime_error("no such drive"); }),
            1);
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "tool: error: no such drive\n");
}

}  // namespace
}  // namespace lidar_stereo_fusion
