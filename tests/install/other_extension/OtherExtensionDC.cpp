// Another extension's plugin, for tests/install/test_plugin_path.py: a user's Extensions folder
// holds it beside KineticFriction's, as it would hold sc3-plugins. One UGen, OtherExtensionDC,
// that outputs 0.25: a render shows whether the server loaded it.
#include <SC_PlugIn.hpp>

static InterfaceTable* ft;

namespace {

struct OtherExtensionDC : public SCUnit {
  OtherExtensionDC() {
    set_calc_function<OtherExtensionDC, &OtherExtensionDC::next>();
    next(1);
  }

  void next(int numSamples) {
    float* output = out(0);
    for (int i = 0; i < numSamples; ++i) output[i] = 0.25f;
  }
};

}  // namespace

PluginLoad(OtherExtension) {
  ft = inTable;
  registerUnit<OtherExtensionDC>(ft, "OtherExtensionDC");
}
