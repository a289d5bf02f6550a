// Where the extension lives, so that a Score render or a server can load its plugin without the
// extension being installed into Platform.userExtensionDir.
KineticFriction {
	// The extension folder: the one holding Classes/, plugins/ and HelpSource/.
	*extensionDir { ^PathName(this.filenameSymbol.asString).pathOnly.dirname }

	*pluginDir { ^this.extensionDir +/+ "plugins" }

	// Adds the plugin folder to options.ugenPluginsPath (keeping the standard plugins) unless
	// scsynth already finds it in an extension folder; returns options.
	*addPluginPath { |options|
		var dirs;
		options = options ?? { ServerOptions.new };
		if(this.isInstalledExtension.not) {
			dirs = options.ugenPluginsPath;
			dirs = case
				{ dirs.isNil } { this.systemPluginDirs }
				{ dirs.isString } { [dirs] }
				{ dirs };
			if(dirs.includesEqual(this.pluginDir).not) { dirs = dirs ++ [this.pluginDir] };
			options.ugenPluginsPath = dirs;
		};
		^options
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
