// Where the extension lives, so that a Score render or a server can load its plugin without the
// extension being installed into Platform.userExtensionDir.
KineticFriction {
	// The extension folder: the one holding Classes/, plugins/ and HelpSource/ (this file sits at the
	// top of Classes/, not in one of its role folders).
	*extensionDir { ^PathName(this.filenameSymbol.asString).pathOnly.dirname }

	*pluginDir { ^this.extensionDir +/+ "plugins" }

	// Adds the plugin folder to options.ugenPluginsPath unless scsynth already finds it in an
	// extension folder; returns options. A ugenPluginsPath (scsynth's -U) replaces scsynth's own
	// search, so where it was nil the folders that search covers come first: other extensions'
	// plugins (sc3-plugins in an Extensions folder, say) keep loading.
	*addPluginPath { |options|
		var dirs;
		options = options ?? { ServerOptions.new };
		if(this.isInstalledExtension.not) {
			dirs = options.ugenPluginsPath;
			dirs = case
				{ dirs.isNil } { this.standardPluginDirs }
				{ dirs.isString } { [dirs] }
				{ dirs };
			if(dirs.includesEqual(this.pluginDir).not) { dirs = dirs ++ [this.pluginDir] };
			options.ugenPluginsPath = dirs;
		};
		^options
	}

	// What scsynth searches without -U, in its order, the folders that exist: its plugins, the
	// system and the user extension folders, then SC_PLUGIN_PATH.
	*standardPluginDirs {
		var fromEnvironment = "SC_PLUGIN_PATH".getenv;
		var dirs = this.systemPluginDirs ++ [Platform.systemExtensionDir, Platform.userExtensionDir]
			++ (fromEnvironment !? { fromEnvironment.split(Platform.pathDelimiter) } ? []);
		^dirs.select { |d| d.notEmpty and: { File.exists(d) } }
	}

	*isInstalledExtension {
		var dir = this.extensionDir.standardizePath;
		^[Platform.userExtensionDir, Platform.systemExtensionDir].any { |ext|
			dir.beginsWith(ext.standardizePath)
		}
	}

	*systemPluginDirs {
		^[Platform.resourceDir +/+ "plugins", "/usr/lib/SuperCollider/plugins", "/usr/local/lib/SuperCollider/plugins"]
			.select { |d| File.exists(d) }
	}
}
