//! Property tests for activecal live in tests/.
