// Transitional (issue 34): the tables moved to eval/report.h and the progress bar to
// io/progress.h. Only src/ros/bag_runner.cpp still includes this header; delete it when
// bag_runner includes io/progress.h.
#pragma once

#include "lidar_stereo_fusion/io/progress.h"
