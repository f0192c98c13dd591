"""Loading tree files: includes, parameters and profiles substituted, every node checked
against its declaration, and every problem reported with its place before anything is built.
"""
