// Another extension's class (tests/install/test_plugin_path.py): its plugin outputs 0.25.
OtherExtensionDC : UGen {
	*ar { ^this.multiNew('audio') }
}
