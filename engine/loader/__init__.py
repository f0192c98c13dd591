"""Loading people's YAML files (trees, profiles, dialogs, scenarios, robot configs).

Every file is parsed keeping each value's place, validated whole, and every problem is
reported as ``file:line:column: message (hint)`` before anything is built.
"""
