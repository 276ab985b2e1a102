"""The `legs` and `legs-flight` studies."""
