// fvcheck reads every variant of a .vtu that VTK 9 itself writes: the example's mesh.vtu is
// re-written by VTK's vtkXMLUnstructuredGridWriter (python3-vtk9) with each compressor (none,
// zlib, LZ4, LZMA), data mode (ascii, binary, appended raw, appended base64), header type
// (UInt32, UInt64) and id type (Int32, Int64), and fvcheck's JSON report must be identical for
// every one of them and for the original. Needs /usr/bin/python3 with vtk (skipped otherwise);
// named VtkValidation* so that scripts/test.sh leaves it out of the ASan pass.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <set>

#include "run_command.hpp"

namespace fs = std::filesystem;

namespace {

const char* kRewrite = R"(import sys, vtk
src, out = sys.argv[1], sys.argv[2]
r = vtk.vtkXMLUnstructuredGridReader()
r.SetFileName(src)
r.Update()
g = r.GetOutput()
comps = [("none", None), ("zlib", vtk.vtkZLibDataCompressor), ("lz4", vtk.vtkLZ4DataCompressor),
         ("lzma", vtk.vtkLZMADataCompressor)]
modes = ["ascii", "binary", "appended", "appended64"]
for cname, C in comps:
    for mode in modes:
        if mode == "ascii" and C is not None:
            continue  # ascii data is never compressed
        for header in (32, 64):
            for ids in (32, 64):
                w = vtk.vtkXMLUnstructuredGridWriter()
                w.SetInputData(g)
                if C is None:
                    w.SetCompressorTypeToNone()
                else:
                    w.SetCompressor(C())
                if mode == "ascii":
                    w.SetDataModeToAscii()
                elif mode == "binary":
                    w.SetDataModeToBinary()
                else:
                    w.SetDataModeToAppended()
                    w.SetEncodeAppendedData(1 if mode == "appended64" else 0)
                w.SetHeaderType(w.UInt32 if header == 32 else w.UInt64)
                w.SetIdType(w.Int32 if ids == 32 else w.Int64)
                name = "%s/%s_%s_h%d_id%d.vtu" % (out, cname, mode, header, ids)
                w.SetFileName(name)
                if w.Write() != 1:
                    sys.exit("write failed: " + name)
                print(name)
)";

bool have_python_vtk() { return std::system("/usr/bin/python3 -c 'import vtk' > /dev/null 2>&1") == 0; }

// fvcheck's JSON report without the file name.
nlohmann::json report_of(const fs::path& vtu, const fs::path& json) {
  const auto r = hm_test::run_command(std::string(HM_BIN_DIR) + "/fvcheck '" + vtu.string() + "' --json '" +
                                      json.string() + "'");
  EXPECT_EQ(r.exit_code, 0) << vtu << "\n" << r.out << r.err;
  nlohmann::json j = nlohmann::json::parse(hm_test::slurp(json), nullptr, false);
  if (j.is_object()) j.erase("source");
  return j;
}

TEST(VtkValidationVariants, EveryVtkWriterVariantGivesTheSameFvcheckReport) {
  if (!have_python_vtk()) GTEST_SKIP() << "/usr/bin/python3 with vtk (python3-vtk9) not installed";
  const fs::path out = hm_test::fresh_dir("vtk_variants");
  ASSERT_EQ(hm_test::run_command(std::string(HM_BIN_DIR) + "/meshgen " + HM_SOURCE_DIR +
                                 "/examples/readme_example.yaml -o '" + out.string() + "'")
                .exit_code,
            0);
  const nlohmann::json reference = report_of(out / "mesh.vtu", out / "reference.json");
  ASSERT_TRUE(reference.is_object());
  EXPECT_TRUE(reference["ok"].get<bool>());
  EXPECT_EQ(reference["transmissibility"]["negative"].get<int>(), 0);

  const fs::path variants = out / "variants";
  fs::create_directories(variants);
  {
    std::ofstream(out / "rewrite.py") << kRewrite;
  }
  const auto w = hm_test::run_command("/usr/bin/python3 '" + (out / "rewrite.py").string() + "' '" +
                                      (out / "mesh.vtu").string() + "' '" + variants.string() + "'");
  ASSERT_EQ(w.exit_code, 0) << w.err;
  int n = 0;
  std::set<std::string> compressors;
  for (const auto& e : fs::directory_iterator(variants)) {
    const std::string text = hm_test::slurp(e.path()).substr(0, 400);
    if (const size_t p = text.find("compressor=\""); p != std::string::npos)
      compressors.insert(text.substr(p + 12, text.find('"', p + 12) - p - 12));
    const nlohmann::json j = report_of(e.path(), out / "variant.json");
    EXPECT_EQ(j, reference) << e.path().filename() << " differs from the original's report";
    ++n;
  }
  EXPECT_EQ(n, 4 * 4 + 3 * 3 * 4);  // none: 4 modes; each compressor: 3 binary modes; x 2 headers x 2 id types
  // VTK wrote what was asked: the three compressors appear in the files' headers.
  EXPECT_EQ(compressors, (std::set<std::string>{"vtkLZ4DataCompressor", "vtkLZMADataCompressor", "vtkZLibDataCompressor"}));
}

}  // namespace
