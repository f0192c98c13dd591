"""Reading a person's files: YAML with every value's place kept, and problems reported as
``file:line:column: message (hint)``. Every loader (trees, profiles, dialogs, scenarios,
robot configs) reads through here.
"""
