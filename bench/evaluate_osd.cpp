// The osd-learn section of make evaluate on its own, for quick checks while changing the
// detector: evaluate_osd DIR [--no-pcl] [--misses] [--pictures OUT_DIR] [--param-name VALUE ...]
#include <cstdio>
#include <iostream>
#include <string>

#include "hough_plane_detector/tools/cli_options.h"
#include "osd_learn.h"

using namespace hough_plane_detector;

int main(int argc, char** argv)
{
  if (argc < 2)
  {
    std::cerr << "usage: evaluate_osd DIR [--no-pcl] [--misses] [--pictures OUT_DIR] [--PARAM VALUE ...]\n";
    return 2;
  }
  const std::string dir = argv[1];
  DetectorParams params;
  bool with_pcl = true, misses = false;
  std::string picture_dir;
  for (int i = 2; i < argc; ++i)
  {
    std::string arg = argv[i];
    if (arg == "--no-pcl")
      with_pcl = false;
    else if (arg == "--misses")
      misses = true;
    else if (arg == "--pictures" && i + 1 < argc)
      picture_dir = argv[++i];
    else if (arg.rfind("--", 0) == 0 && i + 1 < argc)
    {
      std::string name = arg.substr(2), error;
      for (char& c : name)
        if (c == '-') c = '_';
      if (!setDetectorParam(params, name, argv[++i], &error))
      {
        std::cerr << "evaluate_osd: " << error << "\n";
        return 2;
      }
    }
    else
    {
      std::cerr << "evaluate_osd: unexpected argument " << arg << "\n";
      return 2;
    }
  }
  OsdResults results;
  std::string error;
  if (!evaluateOsdLearn(dir, params, with_pcl, picture_dir, results, &error))
  {
    std::cerr << "evaluate_osd: " << error << "\n";
    return 1;
  }
  std::string md = osdLearnMarkdown(results, "");
  if (!misses) md = md.substr(0, md.find("| frame | entry"));
  std::cout << md;
  return 0;
}
