"""Every .schelp file parses with SCDoc, and every code example in it compiles."""
import re

from kfharness import paths, sclang

HELP_DIR = paths.REPO_DIR / "HelpSource"
CLASS_DIR = paths.REPO_DIR / "sc-classes"


def test_every_help_file_parses_and_its_examples_compile():
    files = sorted(HELP_DIR.rglob("*.schelp"))
    assert files, "no help files"
    help_files = ", ".join(sclang.sc_string(p) for p in files)
    out = sclang.run_script(f"""
        var failures = 0, codeBlocks = {{ |node|
            if(node.id == \\CODEBLOCK) {{ [node.text] }} {{
                (node.children ? []).collect(codeBlocks).flatten(1)
            }}
        }};
        [{help_files}].do {{ |path|
            var doc = SCDoc.parseFileFull(path), blocks;
            if(doc.isNil) {{ "HELP-PARSE-FAILED %".format(path).postln; failures = failures + 1 }} {{
                blocks = codeBlocks.(doc);
                blocks.do {{ |code, i|
                    if(code.compile.isNil) {{
                        "HELP-EXAMPLE-FAILED % block %".format(path, i).postln; failures = failures + 1
                    }}
                }};
                "HELP-OK % (% examples)".format(path, blocks.size).postln;
            }}
        }};
        if(failures > 0) {{ Error("% help problems".format(failures)).throw }};
    """)
    for f in files:
        assert f"HELP-OK {f}" in out


def test_every_class_has_a_help_file():
    classes = []
    for sc in [*CLASS_DIR.rglob("*.sc"), *CLASS_DIR.rglob("*.sc.in")]:
        for line in sc.read_text().splitlines():
            if line and not line[0].isspace() and line[0].isupper() and "{" in line:
                classes.append(line.split()[0])
    assert classes
    missing = [c for c in classes if not (HELP_DIR / "Classes" / f"{c}.schelp").exists()]
    assert not missing, f"classes without a help file: {missing}"


def test_no_help_example_sends_the_drive_to_a_numbered_hardware_channel():
    """The drive is a DC level: a help example that sends FrictionDrive to a bare channel number
    (0: usually speakers) pushes a speaker's cone out and holds it. Examples use a private bus, or
    a variable named for the hardware channel of the current source."""
    numbered = re.compile(r"Out\.ar\(\s*\d+\s*,\s*FrictionDrive")
    found = [f"{f.name}: {m.group(0)}" for f in sorted(HELP_DIR.rglob("*.schelp")) for m in numbered.finditer(f.read_text())]
    assert not found, found


def test_the_help_renders_without_warnings_and_documents_every_public_method():
    """SCDoc renders every page of the installed extension as the help browser does, with not one
    warning (an argument named otherwise than the method's, grouped methods of different
    signatures, a broken link, ...), and no class has a public method its page leaves out
    (SCDoc's own count of undocumented methods; a method whose name starts with "pr" is private)."""
    help_dir = paths.extension_dir() / "HelpSource"
    out = sclang.run_script(f"""
        var root = {sclang.sc_string(help_dir)}, ours;
        SCDoc.helpTargetDir = {sclang.sc_string(paths.work_dir() / "help-html")};
        SCDoc.verbosity = 0;
        SCDoc.indexAllDocuments;
        ours = SCDoc.documents.values.select {{ |doc| doc.fullPath.notNil and: {{ doc.fullPath.beginsWith(root) }} }};
        ours.do {{ |doc|
            "KF-RENDER %".format(doc.path).postln;
            SCDoc.parseAndRender(doc);
            if(doc.isClassDoc) {{
                (doc.undoccmethods.collect {{ |m| "*" ++ m }} ++ doc.undocimethods.collect {{ |m| "-" ++ m }}).do {{ |m|
                    if(m.drop(1).beginsWith("pr").not) {{ "KF-UNDOCUMENTED %%".format(doc.title, m).postln }}
                }}
            }}
        }};
    """, include_paths=[paths.extension_dir()])
    rendered = [line.split()[1] for line in out.splitlines() if line.startswith("KF-RENDER ")]
    assert len(rendered) == len(list(help_dir.rglob("*.schelp"))), rendered
    lines = out.splitlines()
    warnings = [lines[i] + " " + (lines[i + 1].strip() if i + 1 < len(lines) else "")
                for i, line in enumerate(lines) if line.startswith("WARNING") and str(help_dir) in line]
    assert not warnings, "SCDoc warns:\n" + "\n".join(warnings)
    undocumented = [line.split(" ", 1)[1] for line in lines if line.startswith("KF-UNDOCUMENTED ")]
    assert not undocumented, f"public methods without help: {undocumented}"


def test_the_overview_links_every_class_and_guide():
    overview = (HELP_DIR / "Overviews" / "KineticFriction.schelp").read_text()
    linked = set(re.findall(r"link::((?:Classes|Guides)/[\w-]+)", overview))
    pages = {f"{f.parent.name}/{f.stem}" for folder in ("Classes", "Guides") for f in (HELP_DIR / folder).glob("*.schelp")}
    assert pages - linked == set(), f"the overview does not link {sorted(pages - linked)}"


# The help is read where the extension is installed, without the repository beside it: it names
# no file of the repository outside the extension folder (which holds Classes/, HelpSource/,
# plugins/, docs/ and udev/), nor the machines the project was tested on.
REPOSITORY_ONLY = re.compile(r"\b(?:tests|bench|scripts|python|device|dsp|host|plugins|cmake|profiles|sc-classes|out)/"
                             r"|\b(?:README|ARCHITECTURE)\b|\.py\b|\.cpp\b|\.hpp\b|\bthis project|virtual machine")


def test_the_help_names_nothing_outside_the_installed_extension():
    found = [f"{f.relative_to(HELP_DIR)}:{n}: {line.strip()}" for f in sorted(HELP_DIR.rglob("*.schelp"))
             for n, line in enumerate(f.read_text().splitlines(), 1) if REPOSITORY_ONLY.search(line)]
    assert not found, "help that speaks of the repository, not to the user:\n" + "\n".join(found)
