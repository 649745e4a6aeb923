// The one public header of the OpenABLE library.
//
//   #include <OpenABLE/OpenABLE.h>
//   openable::Config config = openable::LoadConfig("Config.txt");
//   openable::ProgressReporter progress(std::cerr, true, false);
//   openable::RunResult run = openable::ComputeRun(config, progress);
//   // run.normalized is M' (Eq. 5) over every frame of the run.
#pragma once

#include "OpenABLE/app/run.h"
#include "OpenABLE/base/error.h"
#include "OpenABLE/base/interrupt.h"
#include "OpenABLE/base/output_batch.h"
#include "OpenABLE/base/program.h"
#include "OpenABLE/base/progress.h"
#include "OpenABLE/base/version.h"
#include "OpenABLE/describe/describe.h"
#include "OpenABLE/image/preprocess.h"
#include "OpenABLE/io/frame_source.h"
#include "OpenABLE/online/online.h"
#include "OpenABLE/outputs/matrix_files.h"
#include "OpenABLE/outputs/run_outputs.h"
#include "OpenABLE/reports/evaluation_files.h"
#include "OpenABLE/reports/figures.h"
#include "OpenABLE/run/descriptor_cache.h"
#include "OpenABLE/run/evaluate.h"
#include "OpenABLE/run/pipeline.h"
#include "OpenABLE/stereo/calibration.h"
#include "OpenABLE/stereo/disparity.h"
#include "OpenABLE/stereo/rectification.h"
#include "OpenABLE/stereo/stereo_source.h"
#include "OpenABLE/tuning/sweep.h"
#include "config/config.h"
#include "descriptors/descriptor.h"
#include "descriptors/frame_describer.h"
#include "descriptors/registry.h"
#include "matching/bounded.h"
#include "matching/distances.h"
#include "matching/matrix.h"
#include "matching/normalize.h"
#include "matching/sequence.h"
