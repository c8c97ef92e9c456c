// The osd-learn section of make evaluate on its own, for quick checks while changing the
// detector: evaluate_osd DIR [--no-pcl] [--misses] [--errors] [--noise] [--pictures OUT_DIR] [--PARAM VALUE ...]
#include <cstdio>
#include <iostream>
#include <string>

#include "hough_plane_detector/tools/cli_options.h"
#include "osd_learn.h"

using namespace hough_plane_detector;

int main(int argc, char** argv)
{
  namespace po = boost::program_options;
  std::string dir, picture_dir;
  DetectorParams params;
  po::options_description options("options"), detector_options("detector parameters"), hidden;
  options.add_options()("help,h", "this help")
      ("no-pcl", "skip PCL RANSAC and OMPS")
      ("misses", "list every missed entry with what became of its candidate")
      ("errors", "list every found entry's normal error beside that of the least-squares plane of our labelled pixels")
      ("noise", "the sensor's noise on the table's blocks against the detector's noise model")
      ("pictures", po::value(&picture_dir)->value_name("OUT_DIR"), "write segmented pictures of a few frames there");
  addDetectorParamOptions(params, detector_options, hidden);
  hidden.add_options()("dir", po::value(&dir));
  po::positional_options_description positional;
  positional.add("dir", 1);
  po::options_description all;
  all.add(options).add(detector_options).add(hidden);
  po::variables_map values;
  std::string parse_error;
  if (!parseCommandLine(argc, argv, all, positional, values, &parse_error) || (dir.empty() && !values.count("help")))
  {
    std::cerr << "evaluate_osd: " << (parse_error.empty() ? "no osd-learn folder given" : parse_error) << "\n"
              << "usage: evaluate_osd DIR [options] (see --help)\n";
    return 2;
  }
  if (values.count("help"))
  {
    std::cout << "usage: evaluate_osd DIR [options]\n" << options << detector_options;
    return 0;
  }
  const bool with_pcl = !values.count("no-pcl"), misses = values.count("misses") > 0, errors = values.count("errors") > 0;
  assumeCameraFrame(values, params);
  OsdResults results;
  std::string error;
  if (!evaluateOsdLearn(dir, params, with_pcl, errors, picture_dir, results, &error))
  {
    std::cerr << "evaluate_osd: " << error << "\n";
    return 1;
  }
  std::string md = osdLearnMarkdown(results, "");
  if (!misses) md = md.substr(0, md.find("| frame | entry"));
  std::cout << md;
  if (errors) std::cout << "\n" << osdFitErrorsMarkdown(results);
  if (values.count("noise")) std::cout << "\n" << osdNoiseMarkdown(results);
  return 0;
}
