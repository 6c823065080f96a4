"""What the READMEs tell a user to type is accepted, and what they name exists (no simulator; a few seconds).

In every README and docs page, inside code (fenced blocks and `inline` spans):
- each `./mbot COMMAND` is a command of the mbot script, each `./mbot sim WORLD` a world it knows, and each
  `name:=value` after it an argument that world's launch file declares (./mbot sim refuses any other);
- each `roslaunch PACKAGE FILE name:=value` names a launch file of the workspace that declares those arguments, and
  each `rosrun PACKAGE EXECUTABLE` of a workspace package an executable file of it;
- each `/gazebo/NAME` is a service or topic the bridge's code serves, each `~name` of the bridge's parameter
  table a parameter its node reads, and each part of a `rostopic pub|echo|hz` topic a word of the workspace's
  launch, description, YAML or Python files (a weaker check: the topics come from tags and YAML);
- each workspace path (`src/...`, `tests/...`, `worlds/...`, `docs/...`, `$(find PACKAGE)/...`) and each
  `NAME.world` exists;
and `./mbot --help` lists every command the script dispatches.
Placeholders in capitals (WORLD, SPEC.yaml, OUT) and the user's own files (~/my_ws, $HOME/...) are left out.
"""
import functools
import os
import re
import subprocess
from xml.etree import ElementTree

import pytest

WORKSPACE = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
MBOT = os.path.join(WORKSPACE, "mbot")
SKIPPED = (".venv", ".git", "build", "devel", "out")
BRIDGE_SOURCE = os.path.join(WORKSPACE, "src", "mbot_sim_bridge", "src", "mbot_sim_bridge")
RECONFIGURE_SOURCE = os.path.join(WORKSPACE, "src", "dynamic_reconfigure", "src")


def documents():
    found = []
    for folder, subfolders, names in os.walk(WORKSPACE):
        relative = os.path.relpath(folder, WORKSPACE)
        if relative.split(os.sep)[0] in SKIPPED or relative.startswith(os.path.join("src", "mbot_tests")):
            subfolders.clear()
            continue
        found += [os.path.normpath(os.path.join(relative, name)) for name in names
                  if name == "README.md" or (relative == "docs" and name.endswith(".md"))]
    return sorted(found)


def code_of(text):
    """The text of every fenced block, line by line, and of every inline code span (comments after # dropped)."""
    blocks = re.findall(r"(?ms)^```[a-z]*\n(.*?)^```", text)
    prose = re.sub(r"(?ms)^```[a-z]*\n.*?^```", "", text)
    lines = [re.sub(r"(^|\s)#.*$", "", line) for block in blocks for line in block.splitlines()]
    return lines + [span.replace("\\|", "|") for span in re.findall(r"`([^`\n]+)`", prose)]


def mbot_commands():
    """The commands of the script's last `case "${1:-}"`, the one that dispatches."""
    dispatch = open(MBOT).read().rsplit('case "${1:-}" in', 1)[1]
    return {name for names in re.findall(r"(?m)^  ([a-z|-]+)\)", dispatch) for name in names.split("|")}


def mbot_worlds():
    """World -> (package, launch file), from the script's launch_file_for."""
    body = open(MBOT).read().split("launch_file_for() {", 1)[1].split("\n}", 1)[0]
    return {world: (package, launch) for worlds, package, launch
            in re.findall(r"(?m)^\s+([a-z_|]+)\) echo (\S+) (\S+) ;;", body) for world in worlds.split("|")}


@functools.lru_cache(maxsize=None)
def packages():
    """Package name -> folder, for every package.xml under src/."""
    found = {}
    for folder, subfolders, names in os.walk(os.path.join(WORKSPACE, "src")):
        if "package.xml" in names and not os.path.islink(folder):
            name = ElementTree.parse(os.path.join(folder, "package.xml")).getroot().findtext("name")
            found[name] = folder
        subfolders[:] = [name for name in subfolders if name not in ("test", "__pycache__", "mbot_tests")]
    return found


def launch_file(package, name):
    matches = [os.path.join(folder, name) for folder, _, names in os.walk(packages()[package]) if name in names]
    assert matches, f"{package} has no launch file {name}"
    return matches[0]


@functools.lru_cache(maxsize=None)
def declared_arguments(path):
    """The arguments a launch file takes from its command line: <arg> without a fixed value, outside includes."""
    root = ElementTree.parse(path).getroot()
    inside_includes = {id(arg) for include in root.iter("include") for arg in include.iter("arg")}
    return {arg.get("name") for arg in root.iter("arg") if id(arg) not in inside_includes and "value" not in arg.attrib}


def is_placeholder(word):
    return not word or word[0] in "[<-$~" or word.isupper() or re.search(r"[A-Z]{2}|\||\.\.\.", word)


def assignments(words):
    return [word.split(":=", 1)[0] for word in words if ":=" in word and not word.startswith(("_", "["))]


def check_mbot(words, worlds, commands):
    """`./mbot ...` split into words after ./mbot; returns the problems found."""
    if not words or is_placeholder(words[0]):
        return []
    command = words[0]
    if command not in commands:
        return [f"./mbot {command}: no such command"]
    if command == "sim" and len(words) > 1 and not is_placeholder(words[1]) and words[1] != "--help":
        world = words[1]
        if world not in worlds:
            return [f"./mbot sim {world}: no such world"]
        declared = declared_arguments(launch_file(*worlds[world]))
        return [f"./mbot sim {world} {name}:=: {worlds[world][1]} declares no argument '{name}'"
                for name in assignments(words[2:]) if name not in declared]
    if command == "rviz" and len(words) > 1 and not is_placeholder(words[1]):
        configs = {name[:-5] for folder in packages().values() for _, _, names in os.walk(folder)
                   for name in names if name.endswith(".rviz")}
        return [] if words[1] in configs else [f"./mbot rviz {words[1]}: no such rviz config"]
    return []


def check_roslaunch(words):
    if len(words) < 2 or is_placeholder(words[0]) or words[0] not in packages():
        return []
    path = launch_file(words[0], words[1])
    declared = declared_arguments(path)
    return [f"roslaunch {words[0]} {words[1]} {name}:=: not declared" for name in assignments(words[2:])
            if name not in declared]


def check_rosrun(words):
    if len(words) < 2 or words[0] not in packages() or is_placeholder(words[1]):
        return []
    found = [folder for folder, _, names in os.walk(packages()[words[0]]) if words[1] in names
             and os.access(os.path.join(folder, words[1]), os.X_OK)]
    return [] if found else [f"rosrun {words[0]} {words[1]}: no such executable in {words[0]}"]


def problems_of(line, worlds, commands):
    problems = []
    for tool, checker in (("./mbot", None), ("roslaunch", check_roslaunch), ("rosrun", check_rosrun)):
        for match in re.finditer(rf"(?:^|[\s(;&]){re.escape(tool)}\s+([^;&)#]*)", line):
            words = match.group(1).split()
            problems += check_mbot(words, worlds, commands) if checker is None else checker(words)
    return problems


def path_problems(span, folder=WORKSPACE):
    """Paths are relative to the workspace, or to the document's folder (a package README names its own)."""
    problems = []
    for package, rest in re.findall(r"\$\((?:find|rospack find) ([\w-]+)\)(/[\w./-]*)?", span):
        if package in packages() and rest and not is_placeholder(rest.strip("/")):
            if not os.path.exists(packages()[package] + rest):
                problems.append(f"$(find {package}){rest}: no such file")
    for path in re.findall(r"(?:^|[\s'\"(])((?:src|tests|worlds|docs)/[\w./*-]+)", span):
        path = path.rstrip(".")
        if is_placeholder(path) or "*" in path:
            continue
        if not any(os.path.exists(os.path.join(base, path)) for base in (folder, WORKSPACE)):
            problems.append(f"{path}: no such file or folder")
    return problems


@functools.lru_cache(maxsize=None)
def world_files():
    return {name for folder, _, names in os.walk(WORKSPACE) if not os.path.relpath(folder, WORKSPACE).startswith(
        SKIPPED) for name in names if name.endswith(".world")}


@functools.lru_cache(maxsize=None)
def bridge_names():
    """Every string literal of the bridge's ROS layer and core, and of the dynamic_reconfigure server it runs for
    its physics: what it serves, publishes and reads."""
    names = set()
    for folder, _, files in (*os.walk(BRIDGE_SOURCE), *os.walk(RECONFIGURE_SOURCE)):
        for name in files:
            if name.endswith(".py"):
                names.update(re.findall(r"""["']~?([\w/]+)["']""", open(os.path.join(folder, name)).read()))
    return names


@functools.lru_cache(maxsize=None)
def workspace_names():
    """Every word of the workspace's launch, xacro, URDF, YAML, world and Python files: where a topic's parts
    (a controller's name, a plugin's topic tag, a node's topic) are written."""
    words = set()
    for folder, subfolders, files in os.walk(os.path.join(WORKSPACE, "src")):
        subfolders[:] = [name for name in subfolders if name not in ("__pycache__", "mbot_tests")]
        for name in files:
            if name.endswith((".launch", ".xacro", ".urdf", ".yaml", ".world", ".py", ".sdf")):
                words.update(re.findall(r"\w+", open(os.path.join(folder, name), errors="replace").read()))
    return words


def topic_problems(span):
    """`rostopic pub|echo|hz TOPIC`: every part of TOPIC is a word of the workspace's files."""
    topics = re.findall(r"rostopic (?:pub|echo|hz)(?: -[a-z1-9]+| [0-9.]+)* (/[\w/]+)", span)
    return [f"rostopic {topic}: '{part}' is named nowhere in the workspace" for topic in topics
            for part in topic.strip("/").split("/") if part not in workspace_names()]


def gazebo_problems(span):
    names = re.findall(r"(?<![\w.-])/gazebo/(\w+)\b(?!\.)", span)  # not urdf/gazebo/x.xacro
    return [f"/gazebo/{name}: nothing in the bridge serves it" for name in names
            if name not in bridge_names() and name.lower() == name]


@pytest.mark.parametrize("document", documents())
def test_every_command_path_and_name_in_the_document_exists(document):
    text = open(os.path.join(WORKSPACE, document)).read()
    folder = os.path.dirname(os.path.join(WORKSPACE, document))
    worlds, commands = mbot_worlds(), mbot_commands()
    problems = []
    for line in code_of(text):
        problems += problems_of(line, worlds, commands) + path_problems(line, folder) + gazebo_problems(line)
        problems += topic_problems(line)
        # my_world.world and one-letter names (a.world) are examples of the user's own
        problems += [f"{name}: no such world file" for name in re.findall(r"\b(\w\w+)\.world\b", line)
                     if name + ".world" not in world_files() and not is_placeholder(name)
                     and not name.startswith("my_")]
    assert not problems, f"{document}: " + "; ".join(dict.fromkeys(problems))


def test_the_bridge_parameters_in_its_readme_are_read_by_its_node():
    text = open(os.path.join(WORKSPACE, "src", "mbot_sim_bridge", "README.md")).read()
    node = open(os.path.join(BRIDGE_SOURCE, "node.py")).read()
    parameters = re.findall(r"(?m)^\| `~(\w+)` \| (?:str|bool|int|double) \|", text)
    assert parameters, "the bridge README's parameter table is gone: this test would check nothing"
    assert [name for name in parameters if f'"~{name}"' not in node] == []


def test_mbot_help_lists_every_command_and_the_readme_table_too():
    usage = subprocess.run([MBOT, "--help"], capture_output=True, text=True, check=True).stdout
    readme = open(os.path.join(WORKSPACE, "README.md")).read()
    listed = set(re.findall(r"(?m)^  ([a-z-]+)\b", usage))
    commands = mbot_commands() - {"help"}
    assert commands - listed == set(), "./mbot --help leaves out these commands"
    table = set(re.findall(r"(?m)^\| `\./mbot ([a-z-]+)", readme)) | set(
        re.findall(r"(?m)^\| `\./mbot [^|]*`, `\./mbot ([a-z-]+)", readme))
    assert commands - table == set(), "the README's command table leaves out these commands"


def test_the_checks_catch_a_broken_line():
    """Each check fails on a line a README could get wrong (the checks above would otherwise prove nothing)."""
    worlds, commands = mbot_worlds(), mbot_commands()
    assert problems_of("./mbot sim rover z:=0.13", worlds, commands) == [
        "./mbot sim rover z:=: rover_empty_world.launch declares no argument 'z'"]
    assert problems_of("./mbot simulate empty", worlds, commands) == ["./mbot simulate: no such command"]
    assert problems_of("roslaunch mbot_gazebo mbot_world.launch lockstep:=true colour:=red", worlds, commands) == [
        "roslaunch mbot_gazebo mbot_world.launch colour:=: not declared"]
    assert problems_of("rosrun mbot_gazebo no_such_node", worlds, commands) == [
        "rosrun mbot_gazebo no_such_node: no such executable in mbot_gazebo"]
    assert path_problems("see src/mbot_gazebo/launch/no_such.launch") == [
        "src/mbot_gazebo/launch/no_such.launch: no such file or folder"]
    assert gazebo_problems("rosservice call /gazebo/teleport_model") == [
        "/gazebo/teleport_model: nothing in the bridge serves it"]
    assert topic_problems("rostopic pub -r 10 /mobile_base_controler/cmd_vel geometry_msgs/Twist") == [
        "rostopic /mobile_base_controler/cmd_vel: 'mobile_base_controler' is named nowhere in the workspace"]
