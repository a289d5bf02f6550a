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
