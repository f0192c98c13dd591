"""Wizard-of-oz buttons: a therapist's page of buttons that take over the robot."""
