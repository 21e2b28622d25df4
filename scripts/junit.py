#!/usr/bin/python3
"""JUnit XML helpers for scripts/sanitize.sh and scripts/fuzz.sh (read by scripts/count_tests.py).

  junit.py case OUT.xml SUITE NAME [--failure MESSAGE] [--log FILE] [--tail N] [--time SECONDS]
      writes OUT.xml with one test case SUITE.NAME: passed, or failed with MESSAGE followed by
      the last N (default 40) lines of FILE.
  junit.py failures XML
      prints how many test cases of XML failed or erred; exits 2 when XML is missing or unreadable
      (a process that died while writing it).
  junit.py running LOG
      prints the gtest case that was running when LOG ends ('[ RUN      ]' without its result).
"""
import argparse
import pathlib
import sys
import xml.etree.ElementTree as ElementTree


def tail(path, lines):
    try:
        text = pathlib.Path(path).read_text(errors="replace")
    except OSError as error:
        return f"(no log: {error})"
    return "\n".join(text.splitlines()[-lines:])


def write_case(args):
    suites = ElementTree.Element("testsuites")
    failed = args.failure is not None
    suite = ElementTree.SubElement(suites, "testsuite", name=args.suite, tests="1",
                                   failures="1" if failed else "0", errors="0",
                                   time=f"{args.time:.3f}")
    case = ElementTree.SubElement(suite, "testcase", classname=args.suite, name=args.name,
                                  time=f"{args.time:.3f}")
    if failed:
        message = args.failure
        if args.log:
            message += f"\n--- last {args.tail} lines of {args.log} ---\n" + tail(args.log, args.tail)
        # XML 1.0 has no place for most control characters; sanitizer logs can hold them.
        message = "".join(c if c in "\n\t" or ord(c) >= 32 else "?" for c in message)
        failure = ElementTree.SubElement(case, "failure", message=args.failure.splitlines()[0]
                                         if args.failure else "failed")
        failure.text = message
    pathlib.Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    ElementTree.ElementTree(suites).write(args.out, encoding="utf-8", xml_declaration=True)
    return 0


def count_failures(args):
    try:
        root = ElementTree.parse(args.xml).getroot()
    except (OSError, ElementTree.ParseError):
        return 2
    print(sum(1 for case in root.iter("testcase")
              if case.find("failure") is not None or case.find("error") is not None))
    return 0


def running_case(args):
    running = ""
    for line in tail(args.log, 1 << 30).splitlines():
        if line.startswith("[ RUN      ] "):
            running = line[len("[ RUN      ] "):].strip()
        elif line.startswith(("[       OK ] ", "[  FAILED  ] ", "[  SKIPPED ] ")):
            running = ""
    print(running)
    return 0


def main():
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    commands = parser.add_subparsers(dest="command", required=True)
    case = commands.add_parser("case")
    case.add_argument("out")
    case.add_argument("suite")
    case.add_argument("name")
    case.add_argument("--failure")
    case.add_argument("--log")
    case.add_argument("--tail", type=int, default=40)
    case.add_argument("--time", type=float, default=0.0)
    case.set_defaults(run=write_case)
    failures = commands.add_parser("failures")
    failures.add_argument("xml")
    failures.set_defaults(run=count_failures)
    running = commands.add_parser("running")
    running.add_argument("log")
    running.set_defaults(run=running_case)
    args = parser.parse_args()
    return args.run(args)


if __name__ == "__main__":
    sys.exit(main())
